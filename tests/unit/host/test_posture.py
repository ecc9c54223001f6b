"""host/posture: posture adjustment of 000 §III.B.2, eq. (10), against hand-worked cases."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host import arm_calib, kinematics
from mobigrasp.host import posture as po

G = kinematics.PAPER_000


def test_printed_margins_both_cases():
    # d_alpha > 0: (pi - th2, -th3, -th4)
    assert po.margins_mrad(10, -2000, -500, 1000) == (3142 + 2000, 500, -1000)
    # d_alpha <= 0 (including 0): (th2, pi + th3, pi + th4)
    assert po.margins_mrad(-10, -2000, -500, 1000) == (-2000, 3142 - 500, 3142 + 1000)
    assert po.margins_mrad(0, -2000, -500, 1000) == (-2000, 2642, 4142)


def test_limit_margins():
    assert po.margins_mrad(5, -2000, -500, 1000, "limits") == (2000, 500, 2000)
    assert po.margins_mrad(-5, -2000, -500, 1000, "limits") == (1000, 2300, 1000)
    with pytest.raises(ValueError, match="margin"):
        po.margins_mrad(5, 0, 0, 0, "other")


def test_eq10_paper_coefficients_put_everything_on_theta2():
    # k_theta2 = 1, k_theta3 = k_theta4 = 0: d_theta2 = d_alpha * theta2m / theta2m
    assert po.distribute_alpha(120, -2400, -200, 2300) == (120, 0, 0)
    assert po.distribute_alpha(-75, -2400, -200, 2300) == (-75, 0, 0)


def test_eq10_hand_worked_weights():
    # k = (1, 1, 1) with limit margins, d_alpha = +300 at th = (-2000, -500, 1000):
    # margins (2000, 500, 2000), T_m = 4500 -> (133.3, 33.3, 133.3), remainder on the largest
    p = po.PostureParams(k_theta_q12=(4096, 4096, 4096), margin_mode="limits")
    d = po.distribute_alpha(300, -2000, -500, 1000, p)
    assert sum(d) == 300
    assert abs(d[0] - 133.3) <= 1 and abs(d[1] - 33.3) <= 1 and abs(d[2] - 133.3) <= 1
    # printed margins, k = (1, 0, 1), d_alpha = -200 at th = (-1000, -500, 500):
    # margins (-1000, ., 3642), T_m = 2642 -> d2 = -200 * -1000 / 2642 = +75.7, d4 = -275.7
    p = po.PostureParams(k_theta_q12=(4096, 0, 4096))
    d2, d3, d4 = po.distribute_alpha(-200, -1000, -500, 500, p)
    assert d3 == 0 and abs(d2 - 75.7) <= 1 and abs(d4 + 275.7) <= 1 and d2 + d4 == -200


def test_no_margin_means_no_pitch_change():
    # printed, d_alpha <= 0, th2 = 0 and only k_theta2: T_m = 0
    assert po.distribute_alpha(-100, 0, -500, 1000) == (0, 0, 0)


def test_horizontal_change_faces_the_object():
    obj = kinematics.mm_to_q4((100, 100, -100))  # 45 deg to the right
    adj = po.adjust_posture(G, (-2400, -200, 2300, 200), obj)
    assert adj.d_theta5_mrad == 785 - 200
    assert adj.theta5_mrad == 785


def test_alpha_target_from_geometry_matches_float():
    th2, th3, th4 = -2400, -200, 2300
    obj = (0, 600 * 16, -100 * 16)
    l1, l2, l3 = 95.5, 89.0, 97.0
    a = (th2 + th3 + th4) / 1000
    rc = l1 * math.cos(th4 / 1000) + l2 * math.cos((th4 + th3) / 1000) + l3 * math.cos(a)
    zc = l1 * math.sin(th4 / 1000) + l2 * math.sin((th4 + th3) / 1000) + l3 * math.sin(a)
    want = math.atan2(-100 - zc, 600 - rc) * 1000
    got = po.desired_alpha_mrad(G, th2, th3, th4, obj)
    assert abs(got - want) <= 2
    adj = po.adjust_posture(G, (th2, th3, th4, 0), obj)
    assert adj.d_alpha_mrad == got - (th2 + th3 + th4)
    assert adj.theta2_mrad == th2 + adj.d_alpha_mrad  # paper k: all on the wrist
    assert adj.alpha_lost_mrad == 0


@examples(150)
@given(th2=st.integers(-3000, 0), th3=st.integers(-2800, 0), th4=st.integers(0, 3000),
       th5=st.integers(-1400, 1400), ox=st.integers(-2000, 2000), oy=st.integers(-2000, 2000),
       oz=st.integers(-300, 300), mode=st.sampled_from(po.MARGIN_MODES),
       k=st.tuples(st.integers(0, 4096), st.integers(0, 4096), st.integers(0, 4096)))
def test_targets_always_within_limits(th2, th3, th4, th5, ox, oy, oz, mode, k):
    p = po.PostureParams(k_theta_q12=k, margin_mode=mode)
    adj = po.adjust_posture(G, (th2, th3, th4, th5), (ox * 16, oy * 16, oz * 16), p)
    for ch, v in ((2, adj.theta2_mrad), (3, adj.theta3_mrad), (4, adj.theta4_mrad),
                  (5, adj.theta5_mrad)):
        assert arm_calib.within_limits(ch, v)
    applied = (adj.theta2_mrad + adj.theta3_mrad + adj.theta4_mrad) - (th2 + th3 + th4)
    assert applied + adj.alpha_lost_mrad == adj.d_alpha_mrad


def test_step_cap_and_bad_params():
    p = po.PostureParams(max_step_mrad=50)
    adj = po.adjust_posture(G, (-2400, -200, 2300, 0), kinematics.mm_to_q4((500, 500, 0)), p)
    assert adj.theta5_mrad == 50 and abs(adj.theta2_mrad + 2400) <= 50
    with pytest.raises(ValueError, match="margin_mode"):
        po.PostureParams(margin_mode="x")
    with pytest.raises(ValueError, match="k_theta"):
        po.PostureParams(k_theta_q12=(1, 2))
