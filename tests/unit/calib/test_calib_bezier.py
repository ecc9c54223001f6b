"""The Bezier candidate evaluation in C (hostc/bezier*.c) against the Python planners.

Compared: every candidate's reason and first violated sample exactly, each feasible cost to
1e-12 relative, the chosen candidate exactly. Not bit for bit: numpy evaluates eq. (6)'s power
basis as a matrix product and sums the trapezoid pairwise, the C uses Horner's rule and a
running sum (docs/budget.md); the C's square root is IEEE's, bit for bit.
"""

import math

import numpy as np
import pytest

from mobigrasp.calib import native, planning
from mobigrasp.calib import plan_corpus as pc
from mobigrasp.host.planning.bezier000 import control_points_000
from mobigrasp.host.planning.bezier001 import control_points_001
from mobigrasp.host.planning.candidates import Limits, evaluate_batch
from mobigrasp.host.planning.grasp_circle import end_points
from mobigrasp.host.planning.sonar_regions import SonarConfig, infeasible_regions
from mobigrasp.services.corpus import record

REL = 1e-12


def test_square_root_is_ieee_bit_for_bit():
    rng = np.random.default_rng(7)
    bits = rng.integers(0, 0x7FF0_0000_0000_0000, 20_000, dtype=np.int64)
    xs = np.concatenate([bits.view(np.float64), rng.random(2000), [0.0, 1.0, 2.0, 4.0,
                                                                   5e-324, math.inf]])
    got = np.array([native.dsqrt(x) for x in xs])
    assert np.array_equal(got.view(np.int64), np.sqrt(xs).view(np.int64))
    assert math.isnan(native.dsqrt(-1.0)) and math.isnan(native.dsqrt(math.nan))


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


def _compare(ctrl, n, reasons_py, first_py, reason, first, cost, s_len, s_kint, k1, k2):
    assert [pc.REASONS[r] for r in reason] == list(reasons_py)
    np.testing.assert_array_equal(first, first_py)
    ok = reason == 0
    want = k1 * s_len[ok] + k2 * s_kint[ok]
    np.testing.assert_allclose(cost[ok], want, rtol=REL, atol=0)
    assert np.all(np.isinf(cost[~ok]))


def test_000_candidates_match_python_on_random_plans():
    rng = np.random.default_rng(3)
    seen = set()
    for _ in range(60):
        ctrl = _random_000(rng)
        n = int(rng.integers(2, 65))
        lim = Limits(rng.uniform(0.1, 0.4), rng.uniform(0.01, 0.2), rng.uniform(0.05, 0.5),
                     accel_is_normal=False)
        s, reasons, first = evaluate_batch(ctrl, n, lim)
        best, reason, cfirst, cost = native.bezier000(ctrl, n, planning.limits_words(lim),
                                                      0.5, 0.5)
        _compare(ctrl, n, reasons, first, reason, cfirst, cost, s.arc_length(),
                 s.kappa_integral(), 0.5, 0.5)
        ok = np.nonzero(reason == 0)[0]
        py_cost = np.where(np.array(reasons) == "ok", 0.5 * s.arc_length()
                           + 0.5 * s.kappa_integral(), np.inf)
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
        s, reasons, first = evaluate_batch(ctrl, n, lim,
                                           planning.geometric_checks(obj, l_e, regions))
        geo = planning.geo_words(obj, l_e, regions)
        taken, reason, cfirst, cost = native.bezier001_coarse(
            ctrl, n, planning.limits_words(lim), geo, len(regions), 1, 0, 2**30, 0.8, 0.2)
        assert taken == len(ctrl)
        _compare(ctrl, n, reasons, first, reason, cfirst, cost, s.arc_length(),
                 s.kappa_integral(), 0.8, 0.2)
        seen |= set(reasons)
        # the anytime cut: the curve whose cycles cross the budget and all after it
        spent = np.cumsum(np.minimum(first + 1, n) * 10 + 3)
        cut_at = len(ctrl) // 2
        taken, reason, _, _ = native.bezier001_coarse(
            ctrl, n, planning.limits_words(lim), geo, len(regions), 10, 3,
            int(spent[cut_at]) - 1, 0.8, 0.2)
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
    np.testing.assert_allclose(cost[ok], arrays["cost"][ok], rtol=REL, atol=0)
    assert np.all(np.isinf(cost[~ok]))
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
