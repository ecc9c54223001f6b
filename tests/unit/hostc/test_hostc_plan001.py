"""001's plan whole in C (hostc/plan001.c) against host/planning/bezier001.py plan_001: the
same regions, end points, sampling, candidates and their reasons, costs and D_m, the same
chosen curve, reason text and modelled cost, on hypothesis-drawn scenes and on every plan the
Python made in paper001-sim1."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import event, given
from hypothesis import strategies as st
from plan001_c import params_c
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.host.planning.bezier001 import Params001, plan_001
from mobigrasp.host.planning.bezier_q import CODE, POS_PER_M, Q16, quantize_ctrl
from mobigrasp.host.planning.clearance_q import NO_REGION_Q4
from mobigrasp.host.planning.sonar_regions import InfeasibleRegion
from mobigrasp.host.task.method001 import planner_params_001
from mobigrasp.host.task.params import TaskParams

FFI, C = hostc.lib()
WORK = FFI.new("mg_plan001_work_t *")


def same_plan(start_mm, vel_q4, heading_mrad, target_mm, sonar, params: Params001,
              known: list[InfeasibleRegion]):
    """Plan in both from the same integers; assert every output equal; the C's plan."""
    py = plan_001((start_mm[0] / 1000, start_mm[1] / 1000),
                  (vel_q4[0] / POS_PER_M, vel_q4[1] / POS_PER_M), heading_mrad / 1000,
                  (target_mm[0] / 1000, target_mm[1] / 1000), list(sonar), params, known)
    out = FFI.new("mg_plan001_t *")
    regs = FFI.new("mg_region_t[]", [[r.ox_q4, r.oy_q4, r.lo_urad, r.hi_urad, r.eta_q4,
                                       r.r_r_q4, int(r.arc_bound)] for r in known] or 1)
    C.mg_plan001(params_c(params), [v * 16 for v in start_mm], list(vel_q4), heading_mrad,
                 [v * 16 for v in target_mm], list(sonar), regs, len(known), WORK, out)
    assert out.status != C.MG_PLAN001_TOO_MANY
    reason = FFI.new("char[200]")
    C.mg_plan001_reason(out, reason, 200)
    assert FFI.string(reason).decode() == py.reason
    assert hostc.ops_tuple(out.ops) == py.ops.as_tuple()
    cands = py.candidates
    assert out.n_cand == len(cands)
    if len(cands):
        assert (out.n_samples, out.stride) == (py.n_samples, py.stride)
        assert out.n_regions == len(py.extra["regions"])
        n = out.n_cand
        assert list(WORK.reason[0:n]) == [CODE[r] for r in cands.reasons]
        ctrl = np.array(list(WORK.ctrl[0:12 * n]), dtype=np.int64).reshape(n, 4, 3)
        assert np.array_equal(ctrl, quantize_ctrl(cands.ctrl))
        ok = np.isfinite(cands.cost)
        assert np.array_equal(np.array(list(WORK.cost[0:n]))[ok] / Q16, cands.cost[ok])
        clear = np.array(list(WORK.clear_q4[0:n]))
        assert np.array_equal(np.where(clear == NO_REGION_Q4, np.inf, clear / POS_PER_M),
                              cands.clearance)
    assert (out.best >= 0) == (py.best is not None)
    if py.best is not None:
        assert list(out.best_ctrl) == [int(v) for v in quantize_ctrl(py.best.array).ravel()]
    return out


SONAR = st.lists(st.one_of(st.integers(150, 2600), st.just(65535)), min_size=5, max_size=5)


@examples(40)
@given(st.tuples(st.integers(-500, 500), st.integers(-500, 500)),
       st.tuples(st.integers(-4000, 4000), st.integers(-4000, 4000)),
       st.integers(-3142, 3142), st.tuples(st.integers(-4000, 4000), st.integers(-4000, 4000)),
       SONAR, st.booleans(), st.sampled_from([1, 2]))
def test_plan_001_as_the_python(start, vel, heading, target, sonar, task_params, v0_div):
    """Random scenes: free, with echoes, the object near or behind; the task's parameters or
    001's, v0 as the slow-down level makes it."""
    params = planner_params_001(TaskParams.for_method("001")) if task_params else Params001()
    if v0_div > 1:
        params = Params001(**{**params.__dict__, "v0": params.v0 / v0_div})
    out = same_plan(start, vel, heading, target, sonar, params, [])
    event(f"status {out.status}, regions {min(out.n_regions, 2)}")


def test_plan_001_with_remembered_regions_and_the_cut():
    """Remembered regions (one the object's echo), a budget small enough to cut the coarse
    pass and to stop the fine check."""
    params = planner_params_001(TaskParams.for_method("001"))
    known = [InfeasibleRegion(16_000, 4_000, 200_000, 700_000, 12_000, 3_200, True),
             InfeasibleRegion(0, 0, -300_000, 300_000, 48_000, 3_200, True)]
    out = same_plan((0, 0), (3200, 0), 0, (3000, 0), [65535, 1400, 65535, 1800, 2100],
                    params, known)
    assert out.n_regions >= 2
    small = Params001(**{**params.__dict__, "budget_us": 15_000, "total_budget_us": 30_000,
                         "expected_cost_fraction": 0.0625})
    out = same_plan((0, 0), (3200, 0), 0, (3000, 1100), [2500, 1400, 2500, 1800, 2100], small,
                    [])
    assert out.reasons[C.MG_BUDGET] > 0


def record_plans(mp, calls: list):
    """A recorder (test_hostc_task.recorded_runs) of every plan_001 call: the planners'
    watcher that appends them to ``calls``."""
    from mobigrasp.host.planning.observe import watching

    def watch(name, args, kw, plan):
        if name == "001":
            calls.append((args, kw, plan))
    return watching(watch)


def _replay(calls) -> dict:
    counts: dict[int, int] = {}
    for args, kw, plan in calls:
        start, vel, heading, target, sonar = args[:5]
        params = args[5] if len(args) > 5 else kw.get("params", Params001())
        known = args[6] if len(args) > 6 else kw.get("known_regions") or []
        start_mm = tuple(round(v * 1000) for v in start)
        target_mm = tuple(round(v * 1000) for v in target)
        # the task's SI arguments are whole mm, mrad and 1/16 mm per s
        assert np.allclose(np.array(start_mm) / 1000, start, atol=1e-12)
        out = same_plan(start_mm, tuple(round(v * POS_PER_M) for v in vel),
                        round(heading * 1000), target_mm, sonar, params, list(known))
        assert (out.best >= 0) == (plan.best is not None)
        counts[out.status] = counts.get(out.status, 0) + 1
    return counts


def test_replay_of_the_plans_of_paper001_sim1(shared_recording):
    """Every plan the Python made in paper001-sim1, made again in C: identical."""
    counts = _replay(shared_recording("paper001-sim1", "plans"))
    assert counts.get(C.MG_PLAN001_OK, 0) >= 3, counts


@pytest.mark.slow
def test_replay_of_the_plans_of_paper001_sim2(shared_recording):
    """The same for paper001-sim2, where plans also find no feasible curve."""
    counts = _replay(shared_recording("paper001-sim2", "plans"))
    assert counts.get(C.MG_PLAN001_OK, 0) >= 5 and counts.get(C.MG_PLAN001_NONE_FEASIBLE), counts


def test_more_candidates_than_the_work_area_holds_are_refused():
    """A budget that lets through more than MG_PLAN001_MAX_CAND candidates: the C plans none
    and says so (the Python has no such limit); the shipped parameters stay far below it."""
    params = Params001(expected_cost_fraction=0.0625, n_coarse_min=2)
    out = FFI.new("mg_plan001_t *")
    known = FFI.new("mg_region_t[1]")
    C.mg_plan001(params_c(params), [0, 0], [3200, 0], 0, [60_000 * 16, 0], [65535] * 5, known,
                 0, WORK, out)
    assert out.status == C.MG_PLAN001_TOO_MANY and out.best < 0
    assert plan_001((0, 0), (0.2, 0), 0.0, (60.0, 0.0), [65535] * 5, params).candidates
    reason = FFI.new("char[200]")
    C.mg_plan001_reason(out, reason, 200)
    assert FFI.string(reason).decode() == "too many candidates for the C planner"
    ok = FFI.new("mg_plan001_t *")
    C.mg_plan001(params_c(Params001()), [0, 0], [3200, 0], 0, [60_000 * 16, 0], [65535] * 5,
                 known, 0, WORK, ok)
    assert ok.status != C.MG_PLAN001_TOO_MANY and 0 < ok.n_cand <= 4096  # MG_PLAN001_MAX_CAND
