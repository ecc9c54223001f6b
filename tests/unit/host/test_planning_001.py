"""Planning among obstacles of 001: grasp circle, sonar regions, candidate set, budget."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from region_ref import Ref, grown_m, region_m

from mobigrasp.host.planning.bezier001 import Params001, control_points_001, plan_001
from mobigrasp.host.planning.bezier_q import geo_q, in_regions_q
from mobigrasp.host.planning.grasp_circle import (
    ArmGeometry001,
    arm_height_reach,
    end_points,
    grasp_radius,
)
from mobigrasp.host.planning.sonar_regions import (
    SonarConfig,
    infeasible_regions,
    sub_regions,
)

CLEAR = [2500] * 5


# --- grasp circle, eqs. (5)-(6) -------------------------------------------------------------
def test_grasp_radius_max_is_the_stretched_arm():
    # all links in one line: l_m = sqrt((l1+l2+l3)² − (h_e − h_r)²) = sqrt(0.52² − 0.1²)
    r = grasp_radius(ArmGeometry001())
    assert r.l_max_m == pytest.approx(math.sqrt(0.52**2 - 0.1**2), abs=2e-4)
    assert 0 <= r.l_min_m < 0.01  # the arm can fold back above its base
    assert r.l_e_m == pytest.approx((r.l_max_m + r.l_min_m) / 2)


def test_grasp_radius_against_a_brute_force_3d_scan():
    arm = ArmGeometry001()
    th1 = np.linspace(0, math.pi, 141)
    th = np.linspace(-math.pi / 2, math.pi / 2, 141)
    a, b, c = np.meshgrid(th1, th, th, indexing="ij")
    h, reach = arm_height_reach(arm, a, b, c)
    on = (np.abs(h - arm.h_e) < 0.002) & (reach >= 0)
    r = grasp_radius(arm)
    assert reach[on].max() == pytest.approx(r.l_max_m, abs=0.005)
    assert reach[on].min() == pytest.approx(r.l_min_m, abs=0.01)


def test_grasp_height_out_of_reach_is_an_error():
    with pytest.raises(ValueError, match="out of reach"):
        grasp_radius(ArmGeometry001(h_e=1.0))


def test_end_points_eq6():
    pts = end_points((1.0, 2.0), 0.25, 36)
    assert pts.shape == (36, 2)
    assert np.allclose(np.hypot(pts[:, 0] - 1.0, pts[:, 1] - 2.0), 0.25)
    k = 9  # φ = 2π·9/36 = π/2
    assert pts[k - 1] == pytest.approx([1.0, 2.25])
    assert pts[-1] == pytest.approx([1.25, 2.0])  # k = 36, φ = 2π


# --- sonar sub-regions, eq. (15) -------------------------------------------------------------
def _q4(metres) -> list[int]:
    return [round(m * 16000) for m in metres]


def test_overlapping_cones_give_2ks_minus_1_subregions():
    cfg = SonarConfig()  # A_g = 1.05 > π/4
    regs = sub_regions(cfg, _q4([2.5, 1.0, 2.5, 0.8, 1.2]))
    assert [r.v for r in regs] == list(range(1, 10))
    assert regs[0].lo_urad == pytest.approx((-math.pi / 2 - 0.525) * 1e6, abs=1)
    assert regs[-1].hi_urad == pytest.approx((math.pi / 2 + 0.525) * 1e6, abs=1)
    for a, b in zip(regs, regs[1:], strict=False):
        assert a.hi_urad == b.lo_urad  # contiguous, no gaps
    eta = [r.eta_q4 for r in regs]
    # odd v = 2k−1: ρ_k; even v = 2k: max(ρ_k, ρ_k+1)
    assert eta == _q4([2.5, 2.5, 1.0, 2.5, 2.5, 2.5, 0.8, 1.2, 1.2])


def test_narrow_cones_give_ks_regions():
    cfg = SonarConfig(a_g_rad=0.7)  # <= π/4
    regs = sub_regions(cfg, _q4([1.0, 2.0, 0.5, 2.5, 2.5]))
    assert len(regs) == 5
    assert [r.eta_q4 for r in regs] == _q4([1.0, 2.0, 0.5, 2.5, 2.5])


# --- infeasible regions, eq. (16) -------------------------------------------------------------
def _inside(reg, x: float, y: float) -> bool:
    """Eq. (16) as the planners test it: the region's integer words."""
    return bool(in_regions_q(geo_q((0.0, 0.0), 0.0, [reg]), 1, np.array([round(x * 16000)]),
                             np.array([round(y * 16000)]))[0])


def test_infeasible_region_membership():
    reg = region_m(0.0, 0.0, -0.3, 0.3, 1.0, 0.2)
    w = reg.words
    qx, qy = w.qx / 16000, w.qy / 16000
    assert qy == pytest.approx(0.0) and qx == pytest.approx(-0.2 / math.sin(0.3), abs=2e-4)
    # the apex is R_r away from both original boundary lines (the shifted lines meet there)
    for a in (-0.3, 0.3):
        assert abs(-math.sin(a) * qx + math.cos(a) * qy) == pytest.approx(0.2, abs=2e-4)
    assert _inside(reg, 1.0, 0.0)
    assert _inside(reg, 1.19, 0.0) and not _inside(reg, 1.21, 0.0)
    assert _inside(reg, 0.81, 0.0) and not _inside(reg, 0.79, 0.0)
    # beyond the original boundary but inside the widened one (angle from Q_r)
    y_edge = (1.0 - qx) * math.tan(0.3)
    assert _inside(reg, 1.0, y_edge - 0.01) and not _inside(reg, 1.0, y_edge + 0.01)
    assert 1.0 * math.tan(0.3) < y_edge - 0.01
    assert not _inside(reg, -1.0, 0.0)


def test_regions_from_telemetry_are_in_world_frame_and_bad_values_counted():
    cfg = SonarConfig()
    scan = infeasible_regions(cfg, (1.0, 1.0), math.pi / 2, [2500, 2500, 1200, 0xFFFF, -5])
    assert scan.dropped == 1
    assert len(scan.regions) == 1  # only v = 5 (S_3 alone) holds η < D_e; overlaps take max
    reg = scan.regions[0]
    assert _inside(reg, 1.0, 2.2)  # 1.2 m straight ahead (heading +y)
    assert not _inside(reg, 2.2, 1.0)
    bad = [2500, float("nan"), "x", None, 1200.0]
    assert infeasible_regions(cfg, (0, 0), 0.0, bad).dropped == 3
    with pytest.raises(ValueError, match="5 sonar"):
        infeasible_regions(cfg, (0, 0), 0.0, [1, 2])


@examples(300)
@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(-4, 4), st.floats(0.02, 1.6),
       st.floats(0.05, 2.6), st.floats(0.05, 0.5), st.booleans(), st.integers(0, 2**31))
def test_integer_regions_keep_to_the_float_eq16(ox, oy, lo, width, eta, r_r, arc, seed):
    """The set-up in integers against eq. (16) in floats: a point found inside is inside the
    float region with R_r grown by 3 mm, one found outside is outside it with R_r shrunk by
    3 mm."""
    reg = region_m(ox, oy, lo, lo + width, eta, r_r, arc)
    rng = np.random.default_rng(seed)
    ang = rng.uniform(lo - 0.6, lo + width + 0.6, 400)
    dist = rng.uniform(0.0, eta + r_r + 0.3, 400)
    x, y = ox + dist * np.cos(ang), oy + dist * np.sin(ang)
    inside = in_regions_q(geo_q((0.0, 0.0), 0.0, [reg]), 1, np.rint(x * 16000).astype(np.int64),
                          np.rint(y * 16000).astype(np.int64))
    assert not (inside & ~Ref(grown_m(reg, 0.003)).contains(x, y)).any()
    assert not (~inside & Ref(grown_m(reg, -0.003)).contains(x, y)).any()


# --- candidate set ---------------------------------------------------------------------------
def test_control_points_eqs_8_to_11():
    ends = np.array([[2.0, 0.25]])
    ctrl, us, ks = control_points_001(np.zeros(2), np.array([1.0, 0.0]), ends, (2.0, 0.0),
                                      t3=10.0, n_i=20, dist=2.0, v0=0.2)
    dd_e, dd_s = 2.0 / 20, 2.0 / 80
    u = 5
    row = ctrl[u - 1]
    assert row[1] == pytest.approx([u * dd_s, 0.0, u * dd_s / 0.2])
    assert row[2] == pytest.approx([2.0, 0.25 + u * dd_e, 10.0 - u * dd_e / 0.2])
    assert row[3] == pytest.approx([2.0, 0.25, 10.0])


def test_free_space_plan_ends_on_grasp_circle_without_entering_it():
    plan = plan_001((0, 0), (0.2, 0), 0.0, (3.0, 1.0), CLEAR)
    assert plan.reason == "ok"
    l_e = plan.extra["l_e_m"]
    assert plan.extra["t3_s"] == pytest.approx(math.hypot(3, 1) / 0.2, abs=1e-3)  # eq. (7)
    s = plan.best.sample(400)
    d = np.hypot(s.x - 3.0, s.y - 1.0)
    assert d[-1] == pytest.approx(l_e, abs=2e-4)  # the integer end points: l_e cos, sin in Q12
    assert np.all(d >= l_e - 2e-3)
    prm = Params001()
    assert np.all(s.speed <= prm.v_max + 1e-9)
    assert np.all(s.accel_normal <= prm.a_max * 1.02)  # eq. (14), fine-checked at 48 samples
    # the end direction points at the object
    assert s.heading[-1] == pytest.approx(math.atan2(1.0 - s.y[-1], 3.0 - s.x[-1]), abs=1e-3)


def test_obstacle_is_avoided_and_clearance_filter_applies():
    # obstacle 1.0 m away at 45° right (S_2), object 3 m ahead
    sonar = [2500, 1000, 2500, 2500, 2500]
    plan = plan_001((0, 0), (0.2, 0), 0.0, (3.0, 0.5), sonar)
    assert plan.reason == "ok"
    regions = plan.extra["regions"]
    assert regions
    s = plan.best.sample(300)
    for reg in regions:
        assert not Ref(grown_m(reg, -0.003)).contains(s.x[1:], s.y[1:]).any()
    assert any(c.reason == "obstacle" for c in plan.candidates)
    feas = [c for c in plan.candidates if c.feasible]
    assert any(c.clearance_m > 0.15 for c in feas)
    assert plan.best_candidate.clearance_m > 0.15  # eq. (18): D_m > T_D preferred


def test_clearance_threshold_changes_the_choice():
    sonar = [2500, 1000, 2500, 2500, 2500]
    loose = plan_001((0, 0), (0.2, 0), 0.0, (3.0, 0.5), sonar, Params001(t_d_m=0.0))
    strict = plan_001((0, 0), (0.2, 0), 0.0, (3.0, 0.5), sonar, Params001(t_d_m=0.6))
    assert loose.best is not None and strict.best is not None
    assert loose.best_candidate.clearance_m < 0.6  # the cheapest passes closer than 0.6 m
    assert any(c.clearance_m > 0.6 for c in strict.candidates if c.feasible)
    assert strict.best_candidate.clearance_m > 0.6
    assert strict.best_candidate.cost > loose.best_candidate.cost


def test_echo_of_the_object_itself_is_not_an_obstacle():
    # object 1.5 m ahead: S_3 sees it at ~1.45 m
    plan = plan_001((0, 0), (0.2, 0), 0.0, (1.5, 0.0), [2500, 2500, 1450, 2500, 2500])
    assert plan.reason == "ok"
    assert plan.extra["regions"] == []


@pytest.mark.parametrize("target,sonar", [
    ((3.0, 1.0), CLEAR),
    ((5.0, 2.0), [2500, 1500, 2500, 1800, 2500]),
    ((2.0, -1.0), [900, 1000, 2500, 1200, 1300]),
    ((8.0, 0.0), [2500, 2000, 2500, 1000, 2500]),
])
def test_one_plan_fits_100_ms_of_arm9(target, sonar):
    plan = plan_001((0, 0), (0.2, 0), 0.0, target, sonar)
    assert plan.ops.float_ops == plan.ops.float_divs == 0  # the regions too are in integers
    assert plan.ops.time_us() <= 100_000


def test_all_endpoints_when_asked():
    plan = plan_001((0, 0), (0.2, 0), 0.0, (3.0, 0.0), CLEAR,
                    Params001(endpoint_max_angle_rad=math.pi))
    assert plan.extra["endpoints_kept"] == 36
    assert set(plan.candidates.endpoints.tolist()) <= set(range(1, 37))
    default = plan_001((0, 0), (0.2, 0), 0.0, (3.0, 0.0), CLEAR)
    assert default.extra["endpoints_kept"] == 19  # the half facing the robot


def test_on_the_circle_and_bad_input():
    assert plan_001((0, 0), (0, 0), 0.0, (0.2, 0), CLEAR).best is None
    with pytest.raises(ValueError, match="non-finite"):
        plan_001((0, 0), (0, 0), float("inf"), (2, 0), CLEAR)


def test_anytime_cut_marks_unevaluated_curves_and_keeps_the_budget():
    prm = Params001(budget_us=15_000, total_budget_us=30_000, expected_cost_fraction=0.05)
    plan = plan_001((0, 0), (0.2, 0), 0.0, (3.0, 1.1), [2500, 1400, 2500, 1800, 2100], prm)
    reasons = list(plan.candidates.reasons)
    assert "budget" in reasons
    first_cut = reasons.index("budget")
    assert all(r == "budget" for r in reasons[first_cut:])  # a cut, not holes
    # never evaluated by the C loop: not feasible, not in eq. (18)'s pool
    assert not np.isfinite(plan.candidates.cost[first_cut:]).any()
    assert plan.best_candidate is None or plan.best_candidate.reason == "ok"
    assert plan.ops.time_us() <= 30_000
    # the end point facing the robot is evaluated first: the robot is at 200° seen from the
    # object, end point k_e sits at φ = 10°·k_e (eq. (6), n_e = 36)
    assert plan.candidates.endpoints[0] == 20


def test_shared_echo_option_frees_the_single_sensor_parts():
    rho = _q4([2.5, 1.0, 1.02, 2.5, 2.5])  # S_2 and S_3 hear the same echo: in their overlap
    as_written = [r.eta_q4 for r in sub_regions(SonarConfig(), rho)]
    assert as_written[2:5] == _q4([1.0, 1.02, 1.02])
    opt = [r.eta_q4 for r in sub_regions(SonarConfig(shared_echo_tol_m=0.05), rho)]
    assert opt[3] == _q4([1.02])[0]  # the overlap keeps the echo
    assert opt[2] == opt[4] == _q4([2.5])[0]  # the single-sensor sub-regions are left free
    far = [r.eta_q4 for r in sub_regions(SonarConfig(shared_echo_tol_m=0.05),
                                         _q4([2.5, 1.0, 1.5, 2.5, 2.5]))]
    assert far[2] == _q4([1.0])[0] and far[4] == _q4([1.5])[0]  # eq. (15) as written


def test_sensor_offset_moves_eta_to_the_centre():
    regs = sub_regions(SonarConfig(sensor_offset_m=0.17), _q4([2.5, 1.0, 2.5, 2.5, 2.5]))
    assert regs[2].eta_q4 == _q4([1.17])[0]  # S_2 alone
    assert regs[0].eta_q4 == _q4([2.5])[0]  # no echo stays no echo
