"""The Bezier candidate evaluation in C (hostc/bezier*.c, clearance.c) against the Python planners.

Both compute in fixed point (host/planning/bezier_q.py): every candidate's reason, first
violated sample and Q16 cost are equal, and so is the chosen candidate.
"""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from region_ref import region_m

from mobigrasp.calib import native, planning
from mobigrasp.calib import plan_corpus as pc
from mobigrasp.host.planning import bezier_q
from mobigrasp.host.planning.bezier000 import control_points_000
from mobigrasp.host.planning.bezier001 import control_points_001
from mobigrasp.host.planning.candidates import Limits, evaluate_batch
from mobigrasp.host.planning.clearance_q import clearance_words, path_clearance_q4
from mobigrasp.host.planning.grasp_circle import end_points
from mobigrasp.host.planning.sonar_regions import SonarConfig, infeasible_regions
from mobigrasp.services.corpus import record

K1, K2 = planning.q16(0.5), planning.q16(0.5)


def _random_000(rng):
    p0 = rng.uniform(-2, 2, 2)
    obj = p0 + rng.uniform(0.4, 3.0) * np.array([math.cos(a := rng.uniform(-3, 3)),
                                                 math.sin(a)])
    d3 = (obj - p0) / np.hypot(*(obj - p0))
    b = rng.uniform(-math.pi, math.pi)
    d0 = np.array([math.cos(b), math.sin(b)])
    v0 = rng.uniform(0.05, 0.3)
    dist = float(np.hypot(*(obj - p0)))
    n_i = max(1, int(dist / v0 / 0.3))
    ctrl = control_points_000(p0, d0, obj, d3, dist / v0, n_i, v0)
    back = ctrl[:1].copy()
    back[0, 1, 2] = back[0, 3, 2] * 2  # t(tau) falls after P1
    return np.concatenate([ctrl, back])


def _compare(reasons_py, first_py, reason, first, cost, q, k1, k2):
    assert [pc.REASONS[r] for r in reason] == list(reasons_py)
    np.testing.assert_array_equal(first, first_py)
    ok = reason == 0
    np.testing.assert_array_equal(cost[ok], q.cost_q16(k1, k2)[ok])
    assert np.all(cost[~ok] == planning.INFEASIBLE)


def test_000_candidates_match_python_on_random_plans():
    rng = np.random.default_rng(3)
    seen = set()
    for _ in range(60):
        ctrl = _random_000(rng)
        n = int(rng.integers(2, 65))
        lim = Limits(rng.uniform(0.1, 0.4), rng.uniform(0.01, 0.2), rng.uniform(0.05, 0.5),
                     accel_is_normal=False)
        q, reasons, first = evaluate_batch(ctrl, n, lim)
        best, reason, cfirst, cost = native.bezier000(bezier_q.quantize_ctrl(ctrl), n,
                                                      lim.words(), K1, K2)
        _compare(reasons, first, reason, cfirst, cost, q, K1, K2)
        ok = np.nonzero(reason == 0)[0]
        py_cost = q.cost_q16(K1, K2)
        assert best == (int(ok[np.argmin(py_cost[ok])]) if ok.size else -1)
        seen |= set(reasons)
    assert {"ok", "speed", "accel", "radius", "time_not_increasing"} <= seen


def test_001_candidates_match_python_on_random_scenes():
    rng = np.random.default_rng(5)
    seen = set()
    for trial in range(40):
        p0 = rng.uniform(-1, 1, 2)
        obj = p0 + rng.uniform(0.8, 3.0) * np.array([math.cos(a := rng.uniform(-3, 3)),
                                                     math.sin(a)])
        heading = rng.uniform(-math.pi, math.pi)
        cfg = SonarConfig(arc_angle_bound=bool(trial % 2))
        sonar = [int(v) for v in rng.choice([2500, 400, 700, 1000, 1500], 5)]
        regions = infeasible_regions(cfg, p0, heading, sonar).regions
        l_e, v0 = 0.35, rng.uniform(0.1, 0.3)
        ends = end_points(obj, l_e, 12)[::3]
        dist = float(np.hypot(*(obj - p0)))
        d0 = np.array([math.cos(heading), math.sin(heading)])
        ctrl, _, _ = control_points_001(p0, d0, ends, obj, dist / v0,
                                        max(1, int(dist / v0 / 0.5)), dist, v0)
        far = obj + l_e * (obj - p0) / dist  # a straight line through the grasp circle
        line = np.array([[*(p0 + (far - p0) * f), f * dist / v0] for f in (0, 1 / 3, 2 / 3, 1)])
        ctrl = np.concatenate([ctrl, line[None]])
        n = int(rng.integers(4, 33))
        lim = Limits(0.4, 0.1, None, accel_is_normal=True)
        geometry = planning.geometry(obj, l_e, regions)
        q, reasons, first = evaluate_batch(ctrl, n, lim, geometry)
        geo, cq = geometry.words(), bezier_q.quantize_ctrl(ctrl)
        k1, k2 = planning.q16(0.8), planning.q16(0.2)
        taken, reason, cfirst, cost = native.bezier001_coarse(
            cq, n, lim.words(), geo, len(regions), 1, 0, 2**30, k1, k2)
        assert taken == len(ctrl)
        _compare(reasons, first, reason, cfirst, cost, q, k1, k2)
        seen |= set(reasons)
        # the anytime cut: the curve whose cycles cross the budget and all after it
        spent = np.cumsum(np.minimum(first + 1, n) * 10 + 3)
        cut_at = len(ctrl) // 2
        taken, reason, _, _ = native.bezier001_coarse(
            cq, n, lim.words(), geo, len(regions), 10, 3, int(spent[cut_at]) - 1, k1, k2)
        assert taken == cut_at and np.all(reason[cut_at:] == pc.REASONS.index("budget"))
    assert {"ok", "obstacle", "grasp_circle", "accel"} <= seen


def _check_call(folder, call):
    arrays = pc.load_arrays(folder, call)
    if not len(arrays["ctrl"]):
        return None
    st = planning.setup(call, arrays)
    cp = st.coarse
    # the Python's reasons of the recorded plan, rebuilt from its inputs by planning.setup
    assert [pc.REASONS[r] for r in arrays["reasons"]] == cp.reasons
    if call["planner"] == "000":
        best, reason, first, cost = native.bezier000(cp.ctrl, cp.n, cp.lim, st.k1, st.k2)
        assert best == st.best
    else:
        _, reason, first, cost = native.bezier001_coarse(
            cp.ctrl, cp.n, cp.lim, cp.geo, cp.n_reg, st.per_sample_cycles, st.setup_cycles,
            st.cut_cycles, st.k1, st.k2)
        order = planning.fine_order(cost, st.clearance, st.t_d_m, st.max_fine)
        got, tried = native.bezier001_fine(
            cp.ctrl[order], st.n_fine, st.fine_lim, st.fine_geo, len(st.fine_geo) // 12,
            st.per_sample_cycles, st.setup_cycles, st.worst_us, st.fine_budget_us)
        chosen = None if got < 0 else (int(arrays["us"][order[got]]),
                                       int(arrays["endpoints"][order[got]]))
        assert chosen == st.best
        why = call["result"]["reason"]
        if "fine check" in why:  # the last one tried failed for the reason the Python gives
            assert why.endswith(f"{pc.REASONS[tried[-1]]})")
            assert ("budget spent" in why) == (len(tried) < len(order))
    assert [pc.REASONS[r] for r in reason] == cp.reasons
    evaluated = np.array([r != "budget" for r in cp.reasons])
    np.testing.assert_array_equal(first[evaluated], cp.first[evaluated])
    ok = np.isfinite(arrays["cost"])
    np.testing.assert_array_equal(cost[ok] / bezier_q.Q16, arrays["cost"][ok])
    assert np.all(cost[~ok] == planning.INFEASIBLE)
    return call["planner"]


@pytest.fixture(scope="module")
def plan_slice(tmp_path_factory):
    out = tmp_path_factory.mktemp("planslice")
    record(out, ["paper000-exp1", "paper001-sim1"], time_limit_s=3.0)
    return out


def test_c_matches_every_planner_call_of_a_corpus_slice(plan_slice):
    calls = pc.read_index(plan_slice)["calls"]
    assert {_check_call(plan_slice, c) for c in calls} == {"000", "001"}


@pytest.mark.slow
def test_c_matches_every_planner_call_of_the_corpus(tmp_path):
    record(tmp_path, ["paper000-exp1", "paper000-exp2", "paper001-sim1",
                             "paper001-sim2"])
    calls = pc.read_index(tmp_path)["calls"]
    assert len(calls) >= 20
    assert {_check_call(tmp_path, c) for c in calls} == {"000", "001"}


def _lim_000(v, a, r):
    return Limits(v, a, r, accel_is_normal=False)


_coord = st.floats(-3.0, 3.0, allow_nan=False, width=32)
_time = st.floats(-2.0, 40.0, allow_nan=False, width=32)


@examples(200)
@given(pts=st.lists(st.tuples(_coord, _coord, _time), min_size=4, max_size=4),
       n=st.integers(2, 64), v=st.floats(0.05, 2.0), a=st.floats(0.005, 1.0),
       r=st.one_of(st.none(), st.floats(0.02, 2.0)), normal=st.booleans())
def test_c_equals_python_on_random_curves(pts, n, v, a, r, normal):
    """Any four control points, any limits: the C and the Python decide and cost alike."""
    ctrl = np.array(pts, np.float64)[None]
    lim = Limits(v, a, None if normal else r, accel_is_normal=normal)
    q, reasons, first = evaluate_batch(ctrl, n, lim)
    best, reason, cfirst, cost = native.bezier000(bezier_q.quantize_ctrl(ctrl), n,
                                                  lim.words(), K1, K2)
    _compare(reasons, first, reason, cfirst, cost, q, K1, K2)
    assert best == (0 if reasons == ["ok"] else -1)


@examples(100)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 40), arc=st.booleans(),
       far=st.booleans())
def test_c_equals_python_on_random_scenes_with_regions(seed, n, arc, far):
    """Random sonar scenes and 001 candidates (some far outside the range: reason "range")."""
    rng = np.random.default_rng(seed)
    p0 = rng.uniform(-2, 2, 2) + (200.0 if far else 0.0)
    obj = p0 + rng.uniform(0.6, 3.0) * np.array([math.cos(b := rng.uniform(-3, 3)),
                                                 math.sin(b)])
    heading = rng.uniform(-math.pi, math.pi)
    sonar = [int(v) for v in rng.integers(150, 2600, 5)]
    regions = infeasible_regions(SonarConfig(arc_angle_bound=arc), p0, heading, sonar).regions
    l_e, v0 = 0.35, rng.uniform(0.08, 0.3)
    dist = float(np.hypot(*(obj - p0)))
    d0 = np.array([math.cos(heading), math.sin(heading)])
    ctrl, _, _ = control_points_001(p0, d0, end_points(obj, l_e, 8), obj, dist / v0,
                                    max(1, int(dist / v0 / 0.5)), dist, v0)
    lim = Limits(rng.uniform(0.1, 0.5), rng.uniform(0.02, 0.3), None, accel_is_normal=True)
    geometry = planning.geometry(obj, l_e, regions)
    q, reasons, first = evaluate_batch(ctrl, n, lim, geometry)
    k1, k2 = planning.q16(0.8), planning.q16(0.2)
    _, reason, cfirst, cost = native.bezier001_coarse(
        bezier_q.quantize_ctrl(ctrl), n, lim.words(), geometry.words(), len(regions), 1, 0,
        2**30, k1, k2)
    _compare(reasons, first, reason, cfirst, cost, q, k1, k2)
    if far:
        assert set(reasons) == {"range"}


def test_fixed_point_follows_the_float_reference():
    """The fixed-point speed, accelerations and κ decide as the float formulas of bezier.py
    away from the limits: reasons agree on curves whose float margin exceeds 1 %."""
    from mobigrasp.host.planning.bezier import evaluate, taus

    rng = np.random.default_rng(11)
    agree = total = 0
    for _ in range(300):
        rows = _random_000(rng)
        k = int(rng.integers(len(rows)))
        ctrl = rows[k:k + 1]
        n = 24
        s = evaluate(ctrl, taus(n))
        lim = _lim_000(0.25, 0.04, 0.1)
        _, reasons, _ = evaluate_batch(ctrl, n, lim)
        with np.errstate(invalid="ignore"):
            ratios = np.concatenate([s.speed[0] / lim.v_max,
                                     np.abs(s.accel_tangential[0]) / lim.a_max,
                                     np.abs(s.kappa[0]) * lim.r_min])
        if not np.all(np.isfinite(ratios)) or np.any(np.abs(ratios - 1) < 0.01):
            continue
        total += 1
        float_ok = bool(np.all(ratios < 1)) and bool(np.all(evaluate(ctrl, taus(2001)).t_tau > 0))
        agree += float_ok == (reasons[0] == "ok")
    assert total > 100 and agree == total


@examples(150)
@given(st.lists(st.tuples(st.floats(-5, 5), st.floats(-5, 5), st.floats(-4, 4),
                          st.floats(0.05, 2.5), st.floats(0.05, 2.5), st.floats(0.0, 0.4)),
                max_size=5),
       st.integers(0, 40), st.integers(0, 2**32 - 1))
def test_c_clearance_equals_the_python(regs, n, seed):
    """D_m of eq. (18): hostc/clearance.c gives clearance_q's integers, random regions and
    samples over the whole coordinate range (|x| < 2^21)."""
    regions = [region_m(ox, oy, lo, lo + w, eta, r_r) for ox, oy, lo, w, eta, r_r in regs]
    rng = np.random.default_rng(seed)
    x = rng.integers(-(1 << 21) + 1, 1 << 21, size=(1, n))
    y = rng.integers(-(1 << 21) + 1, 1 << 21, size=(1, n))
    words = clearance_words(regions)
    assert native.path_clearance(words, x[0], y[0]) == int(path_clearance_q4(words, x, y)[0])
