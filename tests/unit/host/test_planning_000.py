"""Bezier approach planning of 000 (§III.B.1): control points, constraints, cost, ARM9 budget."""

import math

import numpy as np
import pytest

from mobigrasp.host.planning.bezier000 import Params000, control_points_000, plan_000


def test_control_points_hand_worked():
    # start (0,0) moving +x, object (2,0), standoff 0.15: P3 = (1.85, 0), |P0P3| = 1.85,
    # t3 = 1.85/0.12 = 15.4167 s, N_i = floor(t3/0.3) = 51, Δd_e = 1.85/51, Δd_s = Δd_e/4.
    plan = plan_000((0, 0), (0.12, 0), (2, 0))
    assert plan.extra["n_i"] == 51
    assert plan.extra["t3_s"] == pytest.approx(1.85 / 0.12, abs=1 / 16000)  # 1/16 ms
    assert len(plan.candidates) == 51
    dd_e = 1.85 / 51
    dd_s = dd_e / 4
    c3 = plan.candidates[2]  # u = 3
    assert c3.u == 3
    p = np.asarray(c3.curve.ctrl)
    q = 2 / 16000  # the integer set-up: two counts of 1/16 mm and 1/16 ms
    assert p[0] == pytest.approx([0, 0, 0])
    assert p[1] == pytest.approx([3 * dd_s, 0, 3 * dd_s / 0.12], abs=q)
    assert p[2] == pytest.approx([1.85 - 3 * dd_e, 0, 1.85 / 0.12 - 3 * dd_e / 0.12], abs=q)
    assert p[3] == pytest.approx([1.85, 0, 1.85 / 0.12], abs=q)


def test_end_speeds_are_v0_and_end_direction_points_at_object():
    plan = plan_000((0, 0), (0, 0.12), (1.5, 1.0))
    assert plan.best is not None
    s = plan.best.sample(64)
    # the integer set-up: directions in Q14, positions and times in 1/16 mm and 1/16 ms
    assert s.speed[0] == pytest.approx(0.12, rel=1e-3)
    assert s.speed[-1] == pytest.approx(0.12, rel=1e-3)  # v3 = v0
    to_obj = math.atan2(1.0, 1.5)
    assert s.heading[-1] == pytest.approx(to_obj, abs=2e-4)
    assert s.heading[0] == pytest.approx(math.pi / 2, abs=2e-4)  # along the start velocity


def test_standing_still_uses_heading():
    plan = plan_000((0, 0), (0, 0), (2, 0), heading_rad=0.5)
    s = plan.best.sample(16)
    assert s.heading[0] == pytest.approx(0.5, abs=5e-4)  # the Q12 table's cos and sin


def test_best_is_min_cost_feasible_and_feasible_ones_meet_constraints():
    prm = Params000()
    plan = plan_000((0, 0), (0.12, 0), (2, 1))
    feas = [c for c in plan.candidates if c.feasible]
    assert feas and len(feas) < len(plan.candidates)  # some are rejected in this case
    assert plan.best_candidate.cost == min(c.cost for c in feas)
    for c in feas:
        s = c.curve.sample(plan.n_samples)
        assert np.all(s.speed <= prm.v_max)
        assert np.all(np.abs(s.accel_tangential) <= prm.a_max)
        assert np.all(np.abs(s.kappa) <= 1 / prm.r_min)
        # the fixed-point cost (length in 1/16 mm, κ in Q16) against the float reference
        assert c.cost == pytest.approx(prm.k1 * s.arc_length() + prm.k2 * s.kappa_integral(),
                                       rel=1e-4)


def test_rejected_candidates_really_violate_their_reason():
    prm = Params000()
    plan = plan_000((0, 0), (0.12, 0), (2, 1))
    checked = 0
    for c in plan.candidates:
        if c.feasible:
            continue
        s = c.curve.sample(plan.n_samples)
        if c.reason == "accel":
            assert np.nanmax(np.abs(s.accel_tangential)) > prm.a_max
        elif c.reason == "radius":
            assert np.nanmax(np.abs(s.kappa)) > 1 / prm.r_min
        elif c.reason == "speed":
            assert np.nanmax(s.speed) > prm.v_max
        checked += 1
    assert checked > 0


@pytest.mark.parametrize("field,value,reason", [
    ("v_max", 0.10, "speed"),  # v0 = 0.12 > Vmax: every curve starts too fast
    ("a_max", 1e-6, "accel"),
    ("r_min", 50.0, "radius"),
])
def test_constraint_violations_are_rejected(field, value, reason):
    prm = Params000(**{field: value})
    plan = plan_000((0, 0), (0.12, 0.0), (2.0, 1.0), prm)
    assert plan.best is None
    assert all(not c.feasible for c in plan.candidates)
    assert reason in plan.reason
    assert any(c.reason == reason for c in plan.candidates)


@pytest.mark.parametrize("dist", [0.5, 2.0, 4.0, 6.0, 12.0])
def test_one_plan_fits_100_ms_of_arm9(dist):
    plan = plan_000((0, 0), (0.12, 0), (dist * 0.8, dist * 0.6))
    assert plan.ops.float_ops == 0 and plan.ops.float_divs == 0  # integer, set-up included
    assert plan.ops.time_us() <= 100_000
    assert plan.n_samples >= Params000().n_samples_min


def test_within_standoff_and_bad_input():
    plan = plan_000((0, 0), (0, 0), (0.1, 0))
    assert plan.best is None and "standoff" in plan.reason
    with pytest.raises(ValueError, match="non-finite"):
        plan_000((0, float("nan")), (0, 0), (1, 0))
    with pytest.raises(ValueError, match="v_max"):
        Params000(v_max=0)


def test_control_points_function_matches_paper_formula():
    p0, d0 = np.array([1.0, 2.0]), np.array([0.0, 1.0])
    p3, d3 = np.array([3.0, 2.0]), np.array([1.0, 0.0])
    ctrl = control_points_000(p0, d0, p3, d3, t3=10.0, n_i=4, v0=0.2)
    dd_e = 2.0 / 4
    u = 2
    assert ctrl[u - 1, 1] == pytest.approx([1.0, 2.0 + u * dd_e / 4, u * dd_e / 4 / 0.2])
    assert ctrl[u - 1, 2] == pytest.approx([3.0 - u * dd_e, 2.0, 10.0 - u * dd_e / 0.2])


def test_batch_ops_charges_only_the_samples_before_an_early_exit():
    from mobigrasp.host.planning.bezier_q import PASS_OPS, sample_ops
    from mobigrasp.host.planning.candidates import batch_ops

    first = np.array([0, 3, 10, 10, 5])  # first violating sample per curve (10 = none)
    kw = {"regions": 2, "grasp_circle": True, "divs_per_sample": 3}
    ref = (sample_ops(1, **kw) + sample_ops(4, **kw) + sample_ops(10, **kw).scaled(2)
           + sample_ops(6, **kw) + PASS_OPS.scaled(2))  # the two that pass: their integrals
    assert batch_ops(first, 10, **kw) == ref
    assert batch_ops(np.array([], dtype=int), 10).cycles() == 0


def test_time_must_increase_between_samples_too():
    from mobigrasp.host.planning.candidates import Limits, evaluate_batch

    # t control points 0, 2, -1.9, 1: t_τ(0) = 6 > 0 and t_τ(1) = 8.7 > 0, but t_τ dips below 0
    ctrl = np.array([[[0, 0, 0], [1, 0, 2], [2, 0, -1.9], [3, 0, 1]]], float)
    tt = np.linspace(0, 1, 2001)
    c = ctrl[0, :, 2]
    dense = 3 * ((1 - tt) ** 2 * (c[1] - c[0]) + 2 * tt * (1 - tt) * (c[2] - c[1])
                 + tt**2 * (c[3] - c[2]))
    assert dense.min() < 0
    _, reasons, first = evaluate_batch(ctrl, 2, Limits(10, 10, None, False))  # τ = 0 and 1 only
    assert reasons == ["time_not_increasing"] and first[0] == 0
