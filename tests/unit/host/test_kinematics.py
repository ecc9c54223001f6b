"""host/kinematics: eq. (3) and (11) of 000 and eq. (4) of 002 against float references."""

import math

from hypothesis import assume, given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host import arm_calib
from mobigrasp.host import kinematics as kin

G000 = kin.PAPER_000
L000 = (95.5, 89.0, 97.0)
L002 = (97.0, 89.0, 95.5)


def fk_float(lengths, t2, t3, t4, t5):
    """Eq. (3) of 000 in float, angles in rad, mm out."""
    l1, l2, l3 = lengths
    a = t2 + t3 + t4
    r = l1 * math.cos(t4) + l2 * math.cos(t4 + t3) + l3 * math.cos(a)
    z = l1 * math.sin(t4) + l2 * math.sin(t4 + t3) + l3 * math.sin(a)
    return r * math.sin(t5), r * math.cos(t5), z


def ik_printed_float(lengths, x, y, z):
    """Eq. (11) of 000 / eq. (4) of 002 exactly as printed (alpha_T = 0), float, rad."""
    l1, l2, l3 = lengths
    t5 = math.atan2(x, y)
    a = y / math.cos(t5) - l3
    b = z
    t3 = -math.acos((a * a + b * b - l1 * l1 - l2 * l2) / (2 * l1 * l2))
    t4 = math.acos(((l1 + l2 * math.cos(t3)) * a + l2 * math.sin(t3) * b)
                   / (l1 * l1 + l2 * l2 + 2 * l1 * l2 * math.cos(t3)))
    return -t3 - t4, t3, t4, t5


def dist_mm(p_q4, q_mm):
    return math.dist([v / 16 for v in p_q4], q_mm)


def test_fk_hand_worked_cases():
    assert kin.fk_mm(G000, 0, 0, 0, 0) == (0, 282, 0)  # 95.5 + 89 + 97 = 281.5 straight ahead
    # shoulder up, elbow level forward, wrist down: r = l2 = 89, z = l1 - l3 = -1.5
    x, y, z = kin.fk_mm_q4(G000, -1571, -1571, 1571, 0)
    assert abs(x) <= 1 and abs(y - 89 * 16) <= 2 and abs(z + 24) <= 2
    # waist +90 deg (clockwise from above) puts the arm on the right, +X_r
    x, y, z = kin.fk_mm_q4(G000, 0, 0, 0, 1000)
    assert x > 0 and abs(x / 16 - 281.5 * math.sin(1.0)) < 0.2


@examples(200)
@given(t2=st.integers(-3000, 0), t3=st.integers(-2800, 0), t4=st.integers(0, 3000),
       t5=st.integers(-1400, 1400))
def test_fk_matches_float_reference(t2, t3, t4, t5):
    ref = fk_float(L000, t2 / 1000, t3 / 1000, t4 / 1000, t5 / 1000)
    assert dist_mm(kin.fk_mm_q4(G000, t2, t3, t4, t5), ref) < 0.25


@examples(200)
@given(t3=st.integers(-2800, -50), t4=st.integers(0, 3000), t5=st.integers(-1400, 1400))
def test_rough_grasp_round_trip_within_1mm(t3, t4, t5):
    """Reachable workspace of the rough grasp: every in-limit pose with alpha = -pi/2.

    Within 50 mrad of the fully stretched elbow 1/32 mm of input rounding moves the elbow angle
    by tens of mrad (cos is flat there), so the angles there are not a fair round trip."""
    t2 = -1571 - t3 - t4
    assume(-3000 <= t2 <= 0)
    target = fk_float(L000, t2 / 1000, t3 / 1000, t4 / 1000, t5 / 1000)
    assume(math.hypot(target[0], target[1]) > 10.0)  # the waist angle is ill-defined near the axis
    res = kin.ik_rough_grasp_000(G000, tuple(round(v * 16) for v in target))
    assert isinstance(res, kin.ArmPose), res
    assert abs(res.alpha_mrad + 1571) <= kin.ALPHA_SNAP_MRAD
    for ch, v in ((2, res.theta2_mrad), (3, res.theta3_mrad), (4, res.theta4_mrad),
                  (5, res.theta5_mrad)):
        assert arm_calib.within_limits(ch, v)
    assert dist_mm(kin.fk_pose_mm_q4(G000, res), target) < 1.0


@examples(200)
@given(x=st.integers(-400, 400), y=st.integers(-400, 400), z=st.integers(-300, 300),
       alpha=st.sampled_from([-1571, -800, 0]))
def test_ik_never_returns_a_pose_outside_limits(x, y, z, alpha):
    res = kin.ik_pitch_mm_q4(G000, (x * 16, y * 16, z * 16), alpha)
    if isinstance(res, kin.Unreachable):
        assert res.reason
        return
    for ch, v in ((2, res.theta2_mrad), (3, res.theta3_mrad), (4, res.theta4_mrad),
                  (5, res.theta5_mrad)):
        assert arm_calib.within_limits(ch, v)
    assert dist_mm(kin.fk_pose_mm_q4(G000, res), (x, y, z)) < 1.0


def test_unreachable_targets_are_explicit():
    far = kin.ik_rough_grasp_000(G000, kin.mm_to_q4((0, 300, -100)))
    assert isinstance(far, kin.Unreachable) and "out of reach" in far.reason
    behind = kin.ik_rough_grasp_000(G000, kin.mm_to_q4((0, -120, -50)))
    assert isinstance(behind, kin.Unreachable) and "theta" in behind.reason
    axis = kin.ik_rough_grasp_000(G000, (0, 0, -50))
    assert isinstance(axis, kin.Unreachable) and "axis" in axis.reason
    close = kin.ik_pitch_mm_q4(G000, kin.mm_to_q4((0, 3, 0)), 0)
    assert isinstance(close, kin.Unreachable)


def test_rough_grasp_matches_paper_formula_with_wrist_point():
    """alpha_T = -pi/2: eq. (11) with the wrist point A = r, B = P_orz + l3 (see docstring)."""
    l1, l2, l3 = L000
    x, y, z = 30.0, 120.0, -60.0
    t5 = math.atan2(x, y)
    a, b = y / math.cos(t5), z + l3
    t3 = -math.acos((a * a + b * b - l1 * l1 - l2 * l2) / (2 * l1 * l2))
    t4 = math.acos(((l1 + l2 * math.cos(t3)) * a + l2 * math.sin(t3) * b)
                   / (l1 * l1 + l2 * l2 + 2 * l1 * l2 * math.cos(t3)))
    t2 = -math.pi / 2 - t3 - t4
    res = kin.ik_rough_grasp_000(G000, tuple(round(v * 16) for v in (x, y, z)))
    assert isinstance(res, kin.ArmPose)
    for got, want in zip((res.theta2_mrad, res.theta3_mrad, res.theta4_mrad, res.theta5_mrad),
                         (t2, t3, t4, t5), strict=True):
        assert abs(got - want * 1000) <= 1.5


def test_002_horizontal_matches_printed_eq4():
    g = kin.PAPER_002
    # targets from in-limit horizontal poses (theta2 <= 0 needs theta3 + theta4 >= 0)
    for t3, t4, t5 in ((-0.8, 1.2, 0.0), (-1.5, 1.6, 0.3), (-0.6, 0.9, -0.9)):
        x, y, z = fk_float(L002, -t3 - t4, t3, t4, t5)
        ref = ik_printed_float(L002, x, y, z)  # (wrist, elbow, shoulder, waist), conventions order
        res = kin.ik_horizontal_002(g, tuple(round(v * 16) for v in (x, y, z)))
        assert isinstance(res, kin.ArmPose), res
        assert res.alpha_mrad == 0  # 002: th1 + th2 + th3 = 0
        got = (res.theta2_mrad, res.theta3_mrad, res.theta4_mrad, res.theta5_mrad)
        for gv, rv in zip(got, ref, strict=True):
            assert abs(gv - rv * 1000) <= 3  # Q4 input rounding moves angles ~1-2 mrad
        n002 = kin.pose_in_002_numbering(res)
        assert n002["theta1_mrad"] == res.theta4_mrad and n002["theta4_mrad"] == res.theta5_mrad
        assert n002["theta1_mrad"] + n002["theta2_mrad"] + n002["theta3_mrad"] == 0
        assert dist_mm(kin.fk_pose_mm_q4(g, res), (x, y, z)) < 1.0
    # below the shoulder a level gripper needs theta2 > 0: outside the conventions limits
    low = kin.ik_horizontal_002(g, kin.mm_to_q4((0, 200, -100)))
    assert isinstance(low, kin.Unreachable) and "theta2" in low.reason


def test_precise_grasp_step_cases():
    s = kin.precise_grasp_step(0, 200, 30)
    assert s.theta1_mrad == 1571 and s.theta5_mrad == 150 and not s.aligned  # step limited
    s = kin.precise_grasp_step(100, -50, 30)
    assert s.theta5_mrad == 50 and not s.aligned
    s = kin.precise_grasp_step(100, 10, 30)
    assert s.theta5_mrad == 100 and s.aligned and s.dz_mm == 0
    s = kin.precise_grasp_step(0, 0, 12)
    assert s.dz_mm < 0 and not s.aligned
    s = kin.precise_grasp_step(0, 0, 55)
    assert s.dz_mm > 0 and not s.aligned
    # a spoke at 80 degrees is the neighbouring spoke at -10 degrees
    s = kin.precise_grasp_step(0, 1396, 30)
    assert s.theta5_mrad == -175 + 25 or s.theta5_mrad < 0
    # never outside the waist limits
    assert kin.precise_grasp_step(1390, 700, 30).theta5_mrad == 1400
    assert kin.spoke_angle_mrad(4096) == 785 and kin.spoke_angle_mrad(0) == 0
