"""Method 001 in C (hostc/task_method001.c with the path approach of hostc/task_approach.c and
the grasp states of hostc/task_grasp.c) against the Python (host/task/method001.py,
approach.py, grasp.py): APPROACH step by step with the same sonar ranges and the same
replanner outcomes give the same transitions, wheels, arm targets, paths, plans and charged
planning time; from the grasp circle on (the look back at the object, the grasp by eq. (11),
LIFT's check) the whole steps give the same outputs and trace detail.

The C's replanner is a declared interface (``mg_replanner001_t``): here both tasks are given the
same scripted outcomes of the replanner's calls (method001.py ``start_001``, ``update_001``,
``straight_clear_001``, ``escape_001``) and the requests are compared; the fallbacks with no
feasible curve (``start_detour``: a lower v0, the back-off, the widest free sector, the
detours) and their drives before the next plan step by step with the Python's."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest
from hypothesis import event, given
from hypothesis import strategies as st
from property_examples import examples
from test_hostc_control import trajectories
from test_hostc_task000 import (
    BROWN,
    CUT,
    DETS000,
    ENCODER,
    NEAR,
    PAIRS,
    RADIALS,
    SPOKES,
    _c_step_inputs,
    _c_task,
    _events,
    _fill_plan,
    _frame000,
    _inputs,
    _path_c,
    _path_py,
    _plus,
    _pose,
    path_step,
    record_path_task,
    replay_path_task,
    start_approach,
)
from test_hostc_task_states import _detail, _step_both, assert_outputs, enter_state

from mobigrasp import hostc
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.control.path_follow import PathFollower, Trajectory
from mobigrasp.host.fixedpoint import cos_q12, sin_q12
from mobigrasp.host.planning.grasp_circle import ArmGeometry001, grasp_radius
from mobigrasp.host.task import Task, TaskInputs, machine, method001
from mobigrasp.host.task.drive import wrap_mrad
from mobigrasp.host.task.method import Method
from mobigrasp.host.task.method000 import Method000
from mobigrasp.host.task.method001 import Method001

FFI, C = hostc.lib()
SETTINGS = examples(100)
CYCLES = C.MG_TASK_PLAN_CYCLES_PER_US
START_CB = ("void(void *, int64_t, const mg_task_inputs_t *, const int32_t *, int32_t, "
            "mg_trajectory_t *, mg_plan_outcome_t *)")
UPDATE_CB = ("void(void *, int64_t, const mg_task_inputs_t *, int32_t, mg_replan001_t *, "
             "mg_trajectory_t *, mg_plan_outcome_t *, mg_ops_t *)")
START_PATH_CB = "void(void *, int64_t)"
CLEAR_CB = "int(void *, const mg_task_inputs_t *, const int32_t *, int32_t, mg_ops_t *)"
ESCAPE_CB = ("int(void *, const mg_task_inputs_t *, const int32_t *, int32_t, int32_t, "
             "int32_t *, mg_ops_t *)")


def _ops_into(c_ops, ops: OpCounts) -> None:
    """Python's op counts into the C's mg_ops_t (the same fields in the same order)."""
    for (name, _), v in zip(FFI.typeof("mg_ops_t").fields, ops.as_tuple(), strict=True):
        setattr(c_ops, name, v)


class _PyReplanner(SimpleNamespace):
    """The Python task's replanner: its curve's start time (replan.py Replanner.start_path)."""

    def start_path(self, t_us: int) -> None:
        self.start_us = t_us


NO_WORK = OpCounts()


class Replanner:
    """Scripted outcomes of the replanner's calls, given in turn to the Python task (through
    method001.py's calls of it) and to the C's (its mg_replanner001_t); the requests of both
    kept, each side in its own list."""

    def __init__(self, starts: list, updates: list, clears: list,
                 escapes: list = ((None, NO_WORK),)) -> None:
        self.script = {"start": starts, "update": updates, "clear": clears, "escape": escapes}
        self.at = {"py": {k: 0 for k in self.script}, "c": {k: 0 for k in self.script}}
        self.requests: dict = {"py": [], "c": []}
        self.py_rp = _PyReplanner(start_us=None)
        self.c_start_us: list = []
        self.callbacks = [FFI.callback(START_CB, self._c_start),
                          FFI.callback(UPDATE_CB, self._c_update),
                          FFI.callback(START_PATH_CB, self._c_start_path),
                          FFI.callback(CLEAR_CB, self._c_clear),
                          FFI.callback(ESCAPE_CB, self._c_escape)]
        self.table = FFI.new("mg_replanner001_t *", self.callbacks)

    def _next(self, side: str, kind: str):
        items = self.script[kind]
        item = items[self.at[side][kind] % len(items)]
        self.at[side][kind] += 1
        return item

    # --- the Python's side: method001.py's functions -------------------------------------
    def py_start(self, now, x, y, h, v, obj, sonar, params):
        self.requests["py"].append(("start", now, x, y, h, v, tuple(obj), tuple(sonar),
                                    round(method001.planner_params_001(self.p).v0 / params.v0)))
        table, v_limit, time_us, reason = self._next("py", "start")
        follower = None if table is None else PathFollower(table, now, v_limit)
        return self.py_rp, follower, OpCounts(alu=time_us * CYCLES), {"reason": reason}

    def py_update(self, rp, now, x, y, h, v, sonar, force=False):
        self.requests["py"].append(("update", now, x, y, h, v, tuple(sonar), bool(force)))
        blocked, replanned, has_curve, has_plan, table, v_limit, ops, reason = self._next(
            "py", "update")
        curve = SimpleNamespace(ctrl=[[0.0, 0.0, 0.0]] * 4) if has_curve else None
        dec = SimpleNamespace(blocked=blocked, replanned=replanned, curve=curve,
                              plan=object() if has_plan else None, reason=reason)
        follower = None if not (replanned and has_curve and table is not None) else \
            PathFollower(table, now, v_limit)
        return dec, follower, ops

    def py_clear(self, rp, x, y, h, sonar, obj, travel):
        self.requests["py"].append(("clear", x, y, h, tuple(sonar), tuple(obj), travel))
        return self._next("py", "clear")

    def py_escape(self, rp, x, y, h, sonar, obj, detour_mm, side=0):
        self.requests["py"].append(("escape", x, y, h, tuple(sonar), tuple(obj), detour_mm,
                                    side))
        return self._next("py", "escape")

    # --- the C's side --------------------------------------------------------------------
    @staticmethod
    def _pose(inp) -> tuple:
        return (inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps)

    @staticmethod
    def _sonar(inp) -> tuple:
        return tuple(inp.sonar_mm[0:inp.n_sonar])

    def _c_start(self, ctx, now, inp, obj, v0_div, traj, o) -> None:
        self.requests["c"].append(("start", now, *self._pose(inp), (obj[0], obj[1]),
                                   self._sonar(inp), v0_div))
        _fill_plan(traj, o, self._next("c", "start"))

    def _c_update(self, ctx, now, inp, force, dec, traj, o, ops) -> None:
        self.requests["c"].append(("update", now, *self._pose(inp), self._sonar(inp),
                                   bool(force)))
        blocked, replanned, has_curve, has_plan, table, v_limit, work, reason = self._next(
            "c", "update")
        dec.blocked, dec.replanned, dec.has_curve, dec.has_plan = (blocked, replanned,
                                                                   has_curve, has_plan)
        path = table if replanned and has_curve else None
        _fill_plan(traj, o, (path, v_limit, 0, reason))
        _ops_into(ops, work)

    def _c_start_path(self, ctx, now) -> None:
        self.c_start_us.append(now)

    def _c_clear(self, ctx, inp, obj, travel, ops) -> int:
        self.requests["c"].append(("clear", *self._pose(inp)[:3], self._sonar(inp),
                                   (obj[0], obj[1]), travel))
        clear, work = self._next("c", "clear")
        _ops_into(ops, work)
        return clear

    def _c_escape(self, ctx, inp, obj, detour_mm, side, heading, ops) -> int:
        self.requests["c"].append(("escape", *self._pose(inp)[:3], self._sonar(inp),
                                   (obj[0], obj[1]), detour_mm, side))
        head, work = self._next("c", "escape")
        _ops_into(ops, work)
        if head is None:
            return 0
        heading[0] = head
        return 1


def _long(table):
    """A reference table 20 times slower: paths followed over many sonar checks."""
    return Trajectory(
        tuple(20 * t for t in table.t_us), table.x_um, table.y_um, table.heading_mrad,
        table.v_mm_s, table.w_mrad_s, table.ops)


TABLES = st.none() | trajectories().map(_long)
# the base anywhere, or with the object this far ahead of the waist (the path cut short with
# the object at ADJUST's goal, 120 mm, the look first from 350 mm)
POSES_001 = st.tuples(NEAR, NEAR, st.integers(-3142, 3141)) | st.tuples(
    st.just("facing"), st.integers(-3142, 3141), st.integers(50, 1500))
REASONS = ["ok", "already within standoff of the object", "speed: 14", "blocked: replanned"]
STARTS = st.lists(st.tuples(TABLES, st.integers(0, 400),
                            st.integers(0, 40_000), st.sampled_from(REASONS)),
                  min_size=1, max_size=4)
WORK = st.builds(OpCounts, alu=st.integers(0, 40_000 * CYCLES), muls=st.integers(0, 5000),
                 float_ops=st.integers(0, 500))
# the decisions of replan.py (blocked, replanned, a curve, a plan made) with the path of a
# replanned one, its wheel limit, the update's ARM9 cycles and its reason
DECISIONS = st.sampled_from([(False, False, True, False), (True, False, True, False),
                             (True, False, False, False), (True, False, False, True)])
UPDATES = st.lists(st.one_of(
    st.tuples(DECISIONS, st.none(), st.integers(0, 400), WORK, st.sampled_from(REASONS)),
    st.tuples(st.just((True, True, True, True)), trajectories().map(_long),
              st.integers(0, 400), WORK, st.sampled_from(REASONS))
).map(lambda u: (*u[0], *u[1:])), min_size=1, max_size=4)
CLEARS = st.lists(st.tuples(st.booleans(), st.builds(OpCounts, alu=st.integers(0, 5000))),
                  min_size=1, max_size=4)
# no ring or 2 to 5 sonars (sonar_angles_mrad: one sonar has no angle)
SONAR = st.lists(st.integers(0, 3000) | st.just(0xFFFF), min_size=0, max_size=5).filter(
    lambda r: len(r) != 1).map(tuple)
# escape_001's headings (or none; beyond +-pi too: wrapped) and their work
ESCAPES = st.lists(st.tuples(st.none() | st.integers(-4000, 4000),
                             st.builds(OpCounts, alu=st.integers(0, 5000))),
                   min_size=1, max_size=4)


def _steps(sonar):
    return st.lists(st.tuples(
        st.sampled_from([20_000, 100_000, 300_000, 600_000]) | st.integers(1, 5_000_000),
        POSES_001, st.integers(-300, 300), sonar, RADIALS, st.none() | st.tuples(NEAR, NEAR)),
        max_size=40)


# rings (of 2 sonars or more, sonar_angles_mrad) with echoes inside R_r (200 mm), the
# object's own among them, and free sectors
GUARD_SONAR = st.lists(st.integers(0, 3000) | st.just(0xFFFF), min_size=2, max_size=5).map(
    tuple) | st.tuples(*[st.sampled_from([0xFFFF, 20, 120, 180, 950, 2500])] * 5)


@SETTINGS
@given(STARTS, UPDATES, CLEARS, ESCAPES, st.tuples(NEAR, NEAR), st.integers(1, 4),
       st.integers(0, 2000), st.booleans(), _steps(SONAR), st.just(80) | st.integers(0, 400))
def test_the_path_approach_of_001(starts, updates, clears, escapes, obj, attempts, direct_mm,
                                  sighted, steps, grasp_height_mm):
    """APPROACH of 001 step by step: the look first at a given object, the wait for a sonar
    sweep, sightings not used in a fast turn, the first plan and the plans of the same
    replanner, the sonar check every replan_period_us (replanned in slices, blocked and kept,
    nothing feasible: stop), a new plan from standstill, the follower never backing up, the
    straight way's check before the direct approach, the fallbacks with no feasible curve (a
    lower v0, the back-off, the widest free sector, the detours of escape_001 on one side, at
    most max_detours) driven before the next plan and, at the path's end, the grasp from the
    grasp circle (ROUGH_GRASP, the estimate the look is to confirm kept, the arrival's error
    from l_e of eq. (5) for the grasp height in the trace)."""
    _approach_001(starts, updates, clears, escapes, obj, attempts, direct_mm, sighted, steps,
                  False, grasp_height_mm)


@SETTINGS
@given(STARTS, UPDATES, CLEARS, ESCAPES, st.tuples(NEAR, NEAR), st.integers(1, 4),
       st.integers(0, 2000), st.booleans(), _steps(GUARD_SONAR))
def test_the_guard_of_001(starts, updates, clears, escapes, obj, attempts, direct_mm, sighted,
                          steps):
    """APPROACH of 001 with its guard after every step (method001.py guard_wheels): a front
    echo below R_r that is not the object's stops the base and drops the path and the plan
    being made, the base turns to the widest free sector and drives out of R_r before the
    next plan (hold_before_plan), the same wheels, transitions, path and trace detail."""
    _approach_001(starts, updates, clears, escapes, obj, attempts, direct_mm, sighted, steps,
                  True)


# no feasible curve most of the time, every failed plan a fallback (one attempt, no direct
# approach), the base at rest between long steps: the fallbacks in turn, their drives, the
# detours up to max_detours
FAILING_STARTS = st.lists(st.tuples(st.none(), st.integers(0, 400), st.integers(0, 40_000),
                                    st.sampled_from(REASONS[2:])), min_size=1, max_size=3).map(
    lambda fails: [*fails, (None, 0, 0, "no feasible curve")])
RARE_STARTS = st.lists(st.tuples(st.none() | trajectories().map(_long), st.integers(0, 400),
                                 st.integers(0, 40_000), st.sampled_from(REASONS[2:])),
                       min_size=1, max_size=4)
NO_CURVE = st.tuples(st.just((True, False, False, True)), st.none(), st.integers(0, 400), WORK,
                     st.sampled_from(REASONS)).map(lambda u: (*u[0], *u[1:]))
FAILING_UPDATES = st.lists(NO_CURVE, min_size=1, max_size=3) | UPDATES
# headings the sonars point along (a detour's turn ends on one of them), or any
RING_HEADINGS = st.sampled_from([-1571, -785, 0, 785, 1571, -3142]) | st.integers(-3142, 3141)
RESTING_STEPS = st.lists(st.tuples(
    st.sampled_from([600_000, 1_000_000]) | st.integers(1, 2_000_000),
    st.tuples(NEAR, NEAR, RING_HEADINGS) | POSES_001 | st.just(("turned",))
    | st.tuples(st.just("along"), st.integers(0, 600)),
    st.integers(-30, 30), GUARD_SONAR, RADIALS, st.none()), min_size=10, max_size=50)


@SETTINGS
@given(FAILING_STARTS | RARE_STARTS, FAILING_UPDATES, CLEARS, ESCAPES, st.tuples(NEAR, NEAR),
       st.booleans(), RESTING_STEPS, st.booleans())
def test_the_fallbacks_of_001(starts, updates, clears, escapes, obj, sighted, steps, guard):
    """No feasible curve, plan after plan: 001's fallbacks step by step (method001.py
    start_detour), each a fallback detail: v0 halved and the replanner started afresh, the
    back-off toward where the last path began (or the next step when that is within 200 mm),
    the turn to the widest free sector, then the detours of escape_001 (the heading found,
    wrapped, its side kept for the next ones; none found: the free sonar nearest the object's
    bearing, or a quarter turn left) up to max_detours, then FAILED; each drive to its end
    before the next plan. The same wheels, transitions, requests, state and detail."""
    _approach_001(starts, updates, clears, escapes, obj, 1, 0, sighted, steps, guard)


FALLBACK_KEYS = ("fallback", "detour", "detour_count")


def _same_fallbacks(c, ms, py) -> None:
    """The method states alike: the fallbacks' counts, v0's divisor, the detours' side and the
    detour being driven."""
    assert (ms.v0_div, ms.fallbacks, ms.detours, ms.detour_side) == (
        py.ms.v0_div, py.ms.fallbacks, py.ms.detours, py.ms.detour_side)
    d = py.ms.detour
    assert (bool(ms.detour.active) and (
        ms.detour.heading_mrad, bool(ms.detour.drive), ms.detour.length_mm,
        bool(ms.detour.has_from), bool(ms.detour.checked))) == (d is not None and (
            d["heading_mrad"], d["drive"], d.get("length_mm", py.p.detour_mm),
            d["from"] is not None, bool(d.get("checked"))))


def _pose_001(py, at: tuple, pose: tuple) -> tuple[int, int, int]:
    """The step's pose: given, facing the object, or where the base was then ("turned": to the
    heading of the detour being driven; "along": that far along its heading)."""
    if pose[0] == "turned":
        return at if py.ms.detour is None else (*at[:2], py.ms.detour["heading_mrad"])
    if pose[0] == "along":
        h = at[2]
        return (at[0] + (pose[1] * cos_q12(h) >> 12), at[1] + (pose[1] * sin_q12(h) >> 12), h)
    return _pose(py.obj, pose)


def _approach_001(starts, updates, clears, escapes, obj, attempts, direct_mm, sighted, steps,
                  guard: bool, grasp_height_mm: int = 80) -> Task:
    py = Task("001", params={"max_plan_attempts": attempts, "direct_max_mm": direct_mm,
                             "max_detours": 2, "grasp_height_mm": grasp_height_mm})
    c = _c_task(py, method="001")
    rp = Replanner(starts, updates, clears, escapes)
    rp.p = py.p
    C.mg_method001_set_replanner(c, rp.table, FFI.NULL)
    py.object_sighted = c.object_sighted = sighted
    start_approach(py, c, obj)  # 001 adds nothing to the path approach's entry (000's)
    ms = FFI.cast("mg_state001_t *", c.ms.bytes)
    now, at = 0, (0, 0, 0)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(method001, "start_001", rp.py_start)
        mp.setattr(method001, "update_001", rp.py_update)
        mp.setattr(method001, "straight_clear_001", rp.py_clear)
        mp.setattr(method001, "escape_001", rp.py_escape)
        for dt, pose, v_mmps, sonar, det, moved_to in steps:
            now += dt
            if moved_to is not None:
                py.obj = moved_to
                c.obj_mm = moved_to
            at = _pose_001(py, at, pose)
            xyhv = (*at, v_mmps)
            py._detail, c.n_notes = {}, 0
            inp = path_step(py, c, now, xyhv, sonar, det, C.mg_task_follow_path)
            assert {k: v for k, v in _detail(c).items() if k in FALLBACK_KEYS} == {
                k: ENCODER.encode(v) for k, v in py._detail.items() if k in FALLBACK_KEYS}
            _same_fallbacks(c, ms, py)
            if "grasp_circle" in py._detail:  # the arrival on the circle, l_e of eq. (5)
                assert _detail(c)["grasp_circle"] == ENCODER.encode(py._detail["grasp_circle"])
                assert ms.circle_l_e_mm == py.ms.circle_l_e_mm
            if guard:
                _guard_step(py, c, now, inp, xyhv)
                _same_fallbacks(c, ms, py)
            assert rp.requests["c"] == rp.requests["py"]
            assert bool(ms.has_replanner) == (py.ms.replanner is not None)
            assert (tuple(ms.path_from_mm) if ms.has_path_from else None) == py.ms.path_from
            assert (tuple(ms.circle_expected_mm) if ms.has_circle_expected else None) \
                == py.ms.circle_expected
            if py.ms.replanner is not None and py.ms.replanner.start_us is not None:
                assert rp.c_start_us[-1] == py.ms.replanner.start_us
            if py.state != "APPROACH":
                break
            py.remember(now, inp)
            C.mg_task_remember(c, now, *xyhv[:3])
    return py


def test_the_curve_of_001_ends_before_the_braked_footprint_reaches_the_object():
    """A straight 20 s curve followed at 200 mm/s: with the object 400 mm ahead of the waist the
    base goes on; 160 mm ahead (beyond ADJUST's goal, 120 mm), the axle ~260 mm from it, ~30 mm
    of braking would bring the 170 mm footprint within 60 mm of it: both end the curve there,
    on the grasp circle."""
    table = Trajectory((0, 10_000_000, 20_000_000), (0, 2_000_000, 4_000_000), (0, 0, 0),
                       (0, 0, 0), (200, 200, 200), (0, 0, 0), OpCounts())
    keep = (False, False, True, False, None, 0, OpCounts(), "ok")
    sonar = (2500,) * 5
    # the first plan after the look at the object and a sonar sweep (200 ms)
    steps = [(20_000, ("facing", 0, 400), 200, sonar, None, None)] * 12 + [
        (20_000, ("facing", 0, 160), 200, sonar, None, None)]
    py = _approach_001([(table, 0, 0, "ok")], [keep] * 12, [(True, OpCounts())],
                       [(None, OpCounts())], (1500, 0), 1, 0, True, steps, False)
    assert py.state == "ROUGH_GRASP" and py.follower is not None
    assert py._detail["grasp_circle"]["waist_mm"] > py.p.grasp_r_mm


def _guard_step(py, c, now: int, inp, xyhv: tuple) -> None:
    """The wheels' last gate after a step on both tasks: the same wheels, transitions, path
    and detail."""
    py._events, py._detail, c.n_events, c.n_notes = [], {}, 0, 0
    py.rules.guard_wheels(py, now, inp)
    c.rules.guard_wheels(c, now, _inputs(xyhv, tuple(inp.sonar_mm)))
    assert _events(c) == py._events
    assert tuple(c.wheels) == py.wheels
    assert _path_c(c) == _path_py(py)
    assert _detail(c) == {k: ENCODER.encode(v) for k, v in py._detail.items()}


@pytest.mark.parametrize("method", ["000", "001", "002"])
def test_the_grasp_hooks_of_the_rows(method):
    """The method table's rows after APPROACH: ROUGH_GRASP's look first (Method.sight_views,
    its detector the dual "+") and the method's decision after it (look_decides), the
    method's own where the Python's is."""
    rules, r = C.mg_task_method_find(method.encode()), Task(method).rules
    assert [tuple(v) for v in rules.sight_views[0:rules.n_sight_views]] == list(r.sight_views)
    assert (rules.sight_result != FFI.NULL) == bool(r.sight_views)
    own = type(r).look_decides is not Method.look_decides
    assert (rules.look_decides != FFI.NULL) == own == (method == "001")


def test_the_step_counts_of_001():
    """What 001's task charges each step besides its plans (a step along the path, a sonar
    the guard looks at): the C's counts equal the Python's; 000's path method charges no step
    along the path."""
    assert hostc.ops_tuple(C.mg_method001_follow_ops()) == method001.FOLLOW_OPS.as_tuple()
    assert (hostc.ops_tuple(C.mg_method001_guard_sonar_ops())
            == method001.GUARD_SONAR_OPS.as_tuple())
    assert C.mg_path000.follow_ops == FFI.NULL and Method000.follow_ops is None
    assert C.mg_path001.follow_ops != FFI.NULL and Method001.follow_ops is method001.FOLLOW_OPS


def _ms001(c):
    return FFI.cast("mg_state001_t *", c.ms.bytes)


def _circle_c(c) -> tuple:
    """What 001 keeps of its arrival on the grasp circle (the C's)."""
    ms = _ms001(c)
    return (tuple(ms.circle_expected_mm) if ms.has_circle_expected else None,
            ms.circle_l_e_mm, bool(ms.ik_grasp), ms.circle_adjusts)


def _circle_py(py) -> tuple:
    return py.ms.circle_expected, py.ms.circle_l_e_mm, py.ms.ik_grasp, py.ms.circle_adjusts


# frames of the look: a dual "+" pair in most (the estimate moves to where it puts the object)
DETS001 = st.fixed_dictionaries({"dual_plus": PAIRS}, optional={
    "spoke": SPOKES, "held_fill": BROWN}) | DETS000


@examples(80)
@given(st.tuples(st.integers(230, 360), st.integers(-60, 60)),
       st.tuples(*[st.integers(-1500, 1500)] * 4), st.booleans(),
       st.none() | st.tuples(st.integers(-20, 20), st.integers(-20, 20))
       | st.tuples(st.integers(-80, 80), st.integers(-80, 80)), st.booleans(),
       st.sampled_from([80, 80, 60, 95]),
       st.lists(st.tuples(st.sampled_from([60_000, 200_000, 200_000, 400_000, 1_100_000]),
                          st.tuples(st.integers(-5, 5), st.integers(-5, 5),
                                    st.integers(-30, 30)),
                          st.booleans(), st.none() | DETS001), min_size=15, max_size=60))
def test_steps_of_001_from_the_grasp_circle(obj, joints, sighted, offset, track,
                                            grasp_height_mm, steps):
    """From ROUGH_GRASP entered on the grasp circle (the estimate the look is to confirm
    ``offset`` from the object's, kept that far from the estimate when ``track``; none: an
    arrival not on the circle), steps with frames of 000's detectors (dual "+" pairs, spokes,
    the held fill), the gripper flag and odometry that drifts: the look back at the object
    and its looks in turn, then the grasp by eq. (11) straight from there (confirmed: the pose
    above the grasp point, the descent, "ik"), or ADJUST (not seen, seen elsewhere, out of
    reach), LOST (never seen) or 000's rough and precise grasp, and LIFT's check: the same
    outputs, detail and 001 state on both tasks, until the task goes back to the search."""
    py = Task("001", params={"grasp_height_mm": grasp_height_mm})
    c = _c_task(py, method="001")
    enter_state(py, c, "ROUGH_GRASP", obj, True, joints, obj, ())
    py.object_sighted = c.object_sighted = sighted
    l_e = round(grasp_radius(ArmGeometry001(h_e=grasp_height_mm / 1000)).l_e_m * 1000)
    ms = _ms001(c)

    def expect(at):
        py.ms.circle_expected = None if at is None else (at[0] + offset[0], at[1] + offset[1])
        ms.has_circle_expected = py.ms.circle_expected is not None
        ms.circle_expected_mm = py.ms.circle_expected or (0, 0)

    if offset is not None:
        py.ms.circle_l_e_mm = ms.circle_l_e_mm = l_e
        expect(obj)
    out = FFI.new("mg_task_outputs_t *")
    now, x, y, h = 0, 0, 0, 0
    for dt, (dx, dy, dh), closed, dets in steps:
        now += dt
        x, y, h = x + dx, y + dy, h + dh
        if track and offset is not None and py.ms.circle_expected is not None:
            expect(py.obj)
        inp = TaskInputs(x_mm=x, y_mm=y, heading_mrad=h, grasp_closed=closed,
                         detections=dets or {})
        res = _step_both(py, c, now, inp, out, _frame000)
        where = (now, py.state, res.detail)
        assert _circle_c(c) == _circle_py(py), where
        assert (c.sight_frames, c.sight_look, c.sight_adjusts, c.lost_in) == (
            py.sight_frames, py.sight_look, py.sight_adjusts,
            -1 if py.lost_in is None else machine.STATES.index(py.lost_in)), where
        assert (tuple(c.grasp_xy_q4) if c.has_grasp_xy else None) == (
            None if py.grasp_xy_q4 is None else tuple(py.grasp_xy_q4)), where
        if py.state in ("SEARCH", "APPROACH"):
            break  # 001's planner is the replanner's (test_the_path_approach_of_001)
    assert c.hist_overflow == 0


@pytest.mark.parametrize(("pair", "grasp_height_mm", "arrived", "sighted", "why", "regrasps"), [
    (None, 80, True, True, "(not seen by the look)", 0),
    (None, 80, False, False, "never seen by the camera: searching before any grasp", 0),
    (None, 80, False, False, "grasp missed at the estimate, object not seen since", 1),
    (None, 80, False, True, "arm at the rough grasp pose", 1),
    ((150, 40, 170, 40, 300), 80, True, True, "(grasp point out of reach: out of reach", 0),
    ((150, 200, 170, 200, 150), 40, True, True, "(no reachable pose above the grasp point)", 0),
    ((150, 200, 170, 200, 150), 80, True, True, "gripper closed on the object", 0)])
def test_the_look_s_outcomes(pair, grasp_height_mm, arrived, sighted, why, regrasps):
    """The look from the grasp circle with the same dual "+" in every frame (or none), the
    estimate it is to confirm kept at the object's: not seen (ADJUST; never seen before and
    not arrived on the circle: LOST; after a grasp that found no evidence, LOST when not seen
    since, else the grasp on the estimate), seen out of reach, no pose above the grasp point (the
    grasp height more than CIRCLE_PRE_MM under the top), confirmed (the grasp by eq. (11), the
    gripper closed): the same steps on both tasks, the outcome's reason among the events."""
    py = Task("001", params={"grasp_height_mm": grasp_height_mm})
    c = _c_task(py, method="001")
    enter_state(py, c, "ROUGH_GRASP", (300, 0), True, (0, -1571, 1571, 0), None, ())
    py.object_sighted = c.object_sighted = sighted
    py.regrasps = c.regrasps = regrasps
    ms = _ms001(c)
    out = FFI.new("mg_task_outputs_t *")
    dets = {} if pair is None else {"dual_plus": _plus(*[16 * v for v in pair[:4]], pair[4])}
    whys = []
    for k in range(1, 60):
        if arrived and py.state == "ROUGH_GRASP":
            py.ms.circle_expected, py.ms.circle_l_e_mm = py.obj, 306
            ms.has_circle_expected, ms.circle_expected_mm, ms.circle_l_e_mm = 1, py.obj, 306
        inp = TaskInputs(x_mm=0, y_mm=0, heading_mrad=0, grasp_closed=py.phase == "close",
                         detections=dets)
        res = _step_both(py, c, k * 200_000, inp, out, _frame000)
        assert _circle_c(c) == _circle_py(py)
        whys += [e.why for e in res.events]
        if py.state in ("SEARCH", "LIFT"):
            break
    assert any(why in w for w in whys), whys


@pytest.mark.parametrize("adjusts", [0, 1, 2])
def test_the_rough_grasp_out_of_reach_on_the_circle(adjusts):
    """On the grasp circle facing past the object (behind and right of the base, no view of
    the look and no rough grasp reachable): ADJUST closes in first, up to MAX_SIGHT_ADJUSTS
    times a grasp, then FAILED; the look after a close-in is not the circle's. The same steps,
    reasons and 001 state on both tasks."""
    py = Task("001")
    c = _c_task(py, method="001")
    enter_state(py, c, "ROUGH_GRASP", (-180, -218), True, (0, -1571, 1571, 0), None, ())
    ms = _ms001(c)
    py.ms.circle_expected, py.ms.circle_l_e_mm = py.obj, 306
    ms.has_circle_expected, ms.circle_expected_mm, ms.circle_l_e_mm = 1, py.obj, 306
    py.sight_adjusts = c.sight_adjusts = adjusts
    out = FFI.new("mg_task_outputs_t *")
    inp = TaskInputs(x_mm=0, y_mm=0, heading_mrad=0)
    res = _step_both(py, c, 200_000, inp, out, _frame000)
    whys = [e.why for e in res.events]
    assert (py.state, c.sight_adjusts, py.sight_adjusts) == (
        ("ADJUST", adjusts + 1, adjusts + 1) if adjusts < 2 else ("FAILED", 2, 2)), whys
    assert any(w.startswith("rough grasp out of reach (out of reach" if adjusts < 2 else
                            "rough grasp IK: out of reach") for w in whys), whys
    py.sight_frames = c.sight_frames = 3
    assert (py.rules.look_decides(py, 400_000, inp),
            C.mg_method001_look_decides(c, 400_000, FFI.new("mg_task_inputs_t *"))) == (False, 0)
    assert _circle_c(c) == _circle_py(py)


def _record001(mp, calls: list) -> None:
    """001's task's calls, and its replanner's (method001.py's calls of it)."""
    wrap = record_path_task(mp, calls)
    wrap(method001, "start_001",
         lambda now, x, y, h, v, obj, sonar, params=None: (
             "start", now, x, y, h, v, tuple(obj), tuple(sonar), params.v0),
         lambda res, *a, **kw: ((None if res[1] is None else res[1].traj,
                                 0 if res[1] is None else res[1].v_limit_mm_s,
                                 res[2].time_us(), res[3]["reason"]),), quiet=True)
    wrap(method001, "update_001",
         lambda rp, now, x, y, h, v, sonar, force=False: (
             "update", now, x, y, h, v, tuple(sonar), bool(force)),
         lambda res, *a, **kw: ((res[0].blocked, res[0].replanned, res[0].curve is not None,
                                 res[0].plan is not None,
                                 None if res[1] is None else res[1].traj,
                                 0 if res[1] is None else res[1].v_limit_mm_s, res[2],
                                 res[0].reason),), quiet=True)
    wrap(method001, "straight_clear_001",
         lambda rp, x, y, h, sonar, obj, travel: (
             "clear", x, y, h, tuple(sonar), tuple(obj), travel),
         lambda res, *a: (res,), quiet=True)
    wrap(Method001, "start_path", lambda rules, t, follower, now: ("start_path", now),
         lambda res, *a: ())
    wrap(method001, "escape_001",
         lambda rp, x, y, h, sonar, obj, detour_mm, side=0: (
             "escape", x, y, h, tuple(sonar), tuple(obj), detour_mm, side),
         lambda res, *a, **kw: (res,), quiet=True)
    wrap(Method001, "start_detour", lambda rules, t, inp: ("detour",), lambda res, *a: (res,))


def record001_steps(mp, calls: list) -> None:
    """001's calls (``_record001``) and the task's whole steps: (now, inputs, outputs)."""
    _record001(mp, calls)
    orig = machine.Task.step

    def step(task, now_us, inputs):
        res = orig(task, now_us, inputs)
        calls.append(("step", now_us, inputs, res))
        return res
    mp.setattr(machine.Task, "step", step)


def _replay001(calls: list) -> tuple[dict, list]:
    """The recorded calls on the C task: APPROACH call by call (replay_path_task) up to its
    arrival on the grasp circle, the replanner's outcomes as the Python's gave them; from
    there the whole steps, ROUGH_GRASP to DONE, each output, the detail and the charged work
    compared. The count of calls of each kind and the states passed through after APPROACH."""
    p = next(r[1] for r in calls if r[0] == "enter_approach")
    base_v0 = method001.planner_params_001(p).v0
    rp = Replanner([r[9] for r in calls if r[0] == "start"],
                   [r[8] for r in calls if r[0] == "update"],
                   [r[7] for r in calls if r[0] == "clear"])
    # the step the path ended on the grasp circle in
    end = next(i for i, r in enumerate(calls) if r[0] == "step" and r[3].state != "APPROACH"
               and r[3].state != "SEARCH")
    assert calls[end][3].state == "ROUGH_GRASP"
    tasks: list = []

    def setup(c):
        tasks.append(c)
        C.mg_method001_set_replanner(c, rp.table, FFI.NULL)
    counts = replay_path_task(calls[:end + 1], "001", setup, C.mg_task_follow_path)
    assert rp.requests["c"] == [
        (*r[:8], round(base_v0 / r[8])) if r[0] == "start" else r[:8 if r[0] == "update" else 7]
        for r in calls[:end] if r[0] in ("start", "update", "clear")]
    assert rp.c_start_us == [r[1] for r in calls[:end] if r[0] == "start_path"]
    c = tasks[0]
    # the arrival's note (eqs. (5)-(6): the axle's distance from the estimate less l_e)
    res = calls[end][3]
    assert _detail(c)["grasp_circle"] == ENCODER.encode(res.detail["grasp_circle"])
    out = FFI.new("mg_task_outputs_t *")
    states = [machine.STATES[c.state]]
    for now, inp, res in (r[1:] for r in calls[end + 1:] if r[0] == "step"):
        cin, _frame_kept = _c_step_inputs(inp)
        C.mg_task_step(c, now, cin, out)
        where = assert_outputs(c, out, now, res)
        assert hostc.ops_tuple(c.path.ops) == res.ops.as_tuple(), where
        if states[-1] != res.state:
            states.append(res.state)
    assert c.hist_overflow == 0 and c.events_lost == 0
    return counts, states


def _replay_run(calls: list) -> None:
    """The recorded calls and steps of a 001 scenario (``record001_steps``) on the C task."""
    counts, states = _replay001(calls)
    assert counts.get("approach", 0) > 20, counts
    assert counts.get("start", 0) >= 1 and counts.get("update", 0) >= 1, counts
    assert "detour" not in counts  # no fallback in this run: its curves all feasible
    assert any(r[0] == "update" and r[8][1] for r in calls)  # a sonar check replanned
    # a plan charged over several steps: a whole slice in a step (with the count of the step
    # along the old path when it is followed meanwhile)
    slice_alu = C.MG_TASK_PLAN_SLICE_US * CYCLES
    assert max(r[15][2] - r[9][2] for r in calls if r[0] == "approach") in (
        slice_alu, slice_alu + method001.FOLLOW_OPS.alu)
    assert "adjust" not in counts, counts
    # the curve followed to its end on the grasp circle, the look confirming the object, the
    # grasp by eq. (11) from there (no ADJUST, no spoke alignment) and the grasp check
    assert states == ["ROUGH_GRASP", "PRECISE_GRASP", "LIFT", "DONE"], states
    details = [r[3].detail for r in calls if r[0] == "step"]
    assert [d["circle_look"]["confirmed"] for d in details if "circle_look" in d] == [True]
    assert [d["grasp_close"] for d in details if "grasp_close" in d] == ["ik"]


def test_replay_of_paper001_sim1(shared_recording):
    """The calls the Python task made in paper001-sim1 replayed on the C task with the same
    inputs and the replanner's outcomes as the Python's gave them: APPROACH (the wait for a
    sweep, the plans, the sonar checks and their replans in slices, the path followed to the
    grasp circle) step by step gives the same outputs, and the C asks the replanner what the
    Python asked it, call by call; from the grasp circle on, the whole steps (the look back at
    the object, the grasp by eq. (11), the lift and the grasp check) give the same outputs."""
    _replay_run(shared_recording("paper001-sim1", "task"))


@pytest.mark.slow
def test_replay_of_paper001_sim2(shared_recording):
    """The same for paper001-sim2 (its longer way round the obstacles, 65 s simulated)."""
    _replay_run(shared_recording("paper001-sim2", "task"))


def _cut_twice(py, c, now: int, inp: TaskInputs, out):
    """The cut symbol in a frame at ``now`` (nothing yet: a symbol in range is cut too as the
    sweep brings it in), not in one a step before CUT_WAIT_US later, then in the frame at
    CUT_WAIT_US (the move off it starts); that step's result."""
    res = _step_both(py, c, now, inp, out, _frame000)
    assert "back_off" not in res.detail and res.wheels_mmps[0] >= 0
    bare = TaskInputs(x_mm=inp.x_mm, y_mm=inp.y_mm, heading_mrad=inp.heading_mrad,
                      sonar_mm=inp.sonar_mm, detections={"radial_symbol": None})
    now += method001.CUT_WAIT_US
    _step_both(py, c, now - 20_000, bare, out, _frame000)
    res = _step_both(py, c, now, inp, out, _frame000)
    assert "back_off" in res.detail
    return res


def _move(res, x: int, y: int, h: int) -> tuple[int, int, int]:
    """Odometry after a step of the wheels: 100 mrad a step turning on the spot (left for a
    right wheel forward), 20 mm a step straight ahead."""
    left, right = res.wheels_mmps
    if left == -right and right:
        return x, y, h + (100 if right > 0 else -100)
    if left == right and left > 0:
        return x + (20 * cos_q12(h) >> 12), y + (20 * sin_q12(h) >> 12), h
    return x, y, h


def test_the_move_of_001_away_from_a_cut_symbol():
    """SEARCH after a loss, far from the start, sees the symbol cut at the left border: the base
    faces away from it (the frame's waist, the half field of view beyond it, and pi), drives
    CUT_AWAY_MM off it at wander_mmps, turns back to face it, stands until a frame taken after
    the stop and looks around again; BACK_OFFS_001 times a run. Both tasks step for step."""
    py = Task("001")
    c = _c_task(py, method="001")
    enter_state(py, c, "SEARCH", None, True, (-2500, -200, 2300, -300), (230, 10),
                ("SEARCH", "LOST"))
    py.counters["lost"] = c.lost = 1
    out = FFI.new("mg_task_outputs_t *")
    free = (0,) * 5
    cut = {"radial_symbol": None, "radial_cut": CUT(x=0, y=120, w=110, h=60, side=-1)}
    nothing = {"radial_symbol": None}
    now, x, y, h = 20_000, 1200, -1700, 1000
    for n in range(1, method001.BACK_OFFS_001 + 1):
        res = _cut_twice(py, c, now, TaskInputs(x_mm=x, y_mm=y, heading_mrad=h, sonar_mm=free,
                                                detections=cut), out)
        now += method001.CUT_WAIT_US
        turn = res.detail["back_off"]["turn_mrad"]
        assert res.detail["back_off"]["n"] == n and turn > 0  # left: cut at the left border
        toward, start = h + turn, (x, y)
        phases = [res.wheels_mmps]
        while res.wheels_mmps != (0, 0):
            now += 20_000
            x, y, h = _move(res, x, y, h)
            res = _step_both(py, c, now, TaskInputs(x_mm=x, y_mm=y, heading_mrad=h,
                                                    sonar_mm=free, detections=cut), out,
                             _frame000)
            if res.wheels_mmps != phases[-1]:
                phases.append(res.wheels_mmps)
        spin = py.p.turn_wheel_mmps
        assert [abs(w[0]) == spin and w[0] == -w[1] for w in phases[:1]] == [True]
        assert (py.p.wander_mmps,) * 2 in phases and phases[-1] == (0, 0)
        driven = math.hypot(x - start[0], y - start[1])
        assert method001.CUT_AWAY_MM <= driven <= method001.CUT_AWAY_MM + 20
        assert abs(wrap_mrad(h - toward)) <= 60  # facing the symbol again
        stopped = now
        while now < stopped + py.p.frame_latency_us:  # frames taken before the stop
            now += 20_000
            res = _step_both(py, c, now, TaskInputs(x_mm=x, y_mm=y, heading_mrad=h,
                                                    sonar_mm=free, detections=nothing), out,
                             _frame000)
            assert res.wheels_mmps == (0, 0)
        assert py.ms.back_off is None and py.ms.back_offs == _ms001(c).cut.back_offs == n
    for dt in (20_000, method001.CUT_WAIT_US):  # no more this run
        res = _step_both(py, c, now + dt, TaskInputs(x_mm=x, y_mm=y, heading_mrad=h,
                                                     sonar_mm=free, detections=cut), out,
                         _frame000)
        assert "back_off" not in res.detail


def test_the_move_of_001_off_an_estimate_too_near_to_be_read():
    """SEARCH after a loss, the object never seen by the camera and its estimate 230 mm from
    the axle: the look-around there (turns_per_wander cycles) sees nothing, not even a cut.
    Instead of the wander's first leg the base faces away from the estimate, drives
    CUT_AWAY_MM off it, turns back to face it, stands until a frame taken after the stop and
    looks around again; the estimate then beyond UNSEEN_NEAR_MM, once. Both tasks step for
    step."""
    py = Task("001")
    c = _c_task(py, method="001")
    enter_state(py, c, "SEARCH", (-200, 120), True, (-2500, -200, 2300, -300), (230, 10), ())
    py.counters["lost"] = c.lost = 1
    assert not py.object_sighted
    out = FFI.new("mg_task_outputs_t *")
    free, nothing = (0,) * 5, {"radial_symbol": None}
    now, x, y, h = 0, 0, 0, 300
    looked = None  # when the look-around here was over
    res = None
    while "back_off_unseen" not in (res.detail if res else {}):
        assert now < 60_000_000 and py.state == "SEARCH"
        if looked is None and py.search is not None \
                and py.search.cycle >= py.search.params.turns_per_wander:
            looked = now
        now += 20_000
        if res is not None:
            x, y, h = _move(res, x, y, h)
        res = _step_both(py, c, now, TaskInputs(x_mm=x, y_mm=y, heading_mrad=wrap_mrad(h),
                                                sonar_mm=free, detections=nothing), out,
                         _frame000)
    assert looked is not None and now - looked <= 20_000  # at the look-around's end
    unseen = res.detail["back_off_unseen"]
    assert unseen["n"] == 1 and unseen["dist_mm"] == math.isqrt((x + 200) ** 2 + (y - 120) ** 2)
    toward = wrap_mrad(h) + unseen["turn_mrad"]
    assert abs(wrap_mrad(toward - round(math.atan2(120 - y, -200 - x) * 1000))) <= 2
    start, phases = (x, y), [res.wheels_mmps]
    while res.wheels_mmps != (0, 0):
        now += 20_000
        x, y, h = _move(res, x, y, h)
        res = _step_both(py, c, now, TaskInputs(x_mm=x, y_mm=y, heading_mrad=wrap_mrad(h),
                                                sonar_mm=free, detections=nothing), out,
                         _frame000)
        if res.wheels_mmps != phases[-1]:
            phases.append(res.wheels_mmps)
    assert (py.p.wander_mmps,) * 2 in phases
    driven = math.hypot(x - start[0], y - start[1])
    assert method001.CUT_AWAY_MM <= driven <= method001.CUT_AWAY_MM + 20
    assert math.hypot(x + 200, y - 120) >= method001.UNSEEN_NEAR_MM  # away from the estimate
    assert abs(wrap_mrad(h - toward)) <= 100  # facing it again (100 mrad a turning step)
    for _ in range(3000):  # a new look-around from here, and no second move
        now += 20_000
        x, y, h = _move(res, x, y, h)
        res = _step_both(py, c, now, TaskInputs(x_mm=x, y_mm=y, heading_mrad=wrap_mrad(h),
                                                sonar_mm=free, detections=nothing), out,
                         _frame000)
        assert "back_off_unseen" not in res.detail and "back_off" not in res.detail
    assert py.ms.back_offs == _ms001(c).cut.back_offs == 1


@SETTINGS
@given(st.booleans(), st.tuples(*[st.integers(-1500, 1500)] * 4),
       st.lists(st.tuples(st.sampled_from([20_000, 20_000, 60_000, 500_000, 2_000_000]),
                          st.tuples(st.integers(-30, 30), st.integers(-30, 30),
                                    st.integers(-200, 200)),
                          SONAR, st.none() | DETS000), min_size=1, max_size=60),
       st.none() | st.tuples(st.integers(-600, 600), st.integers(-600, 600)))
def test_steps_of_001_in_search(lost, joints, steps, obj):
    """SEARCH of 001 (after a loss or not, with an estimate of an object never seen or none)
    with odometry that wanders, sonar rings and frames of 000's detectors, the cut symbol among
    them: the same outputs and detail on both tasks, to the object found."""
    py = Task("001")
    c = _c_task(py, method="001")
    enter_state(py, c, "SEARCH", obj, True, joints, (230, 10), ("SEARCH", "LOST"))
    py.counters["lost"] = c.lost = int(lost)
    out = FFI.new("mg_task_outputs_t *")
    now, x, y, h = 0, 0, 0, 0
    for dt, (dx, dy, dh), sonar, dets in steps:
        now += dt
        x, y, h = x + dx, y + dy, h + dh
        _step_both(py, c, now, TaskInputs(x_mm=x, y_mm=y, heading_mrad=h, sonar_mm=sonar,
                                          detections=dets), out, _frame000)
        assert (py.ms.back_offs, py.ms.back_off is None) == (_ms001(c).cut.back_offs,
                                                           _ms001(c).cut.phase == 0)
        if py.state != "SEARCH":  # found: APPROACH's plans are the tests' above
            break
    event(f"back-offs {py.ms.back_offs}")


def test_the_move_away_stops_for_an_echo_ahead():
    """The drive off a cut symbol stops short for an echo straight ahead (the sonars watch the
    way: its detour's rule), then turns back as after the whole drive."""
    py = Task("001")
    c = _c_task(py, method="001")
    enter_state(py, c, "SEARCH", None, True, (-2500, -200, 2300, 0), (230, 10),
                ("SEARCH", "LOST"))
    out = FFI.new("mg_task_outputs_t *")
    cut = {"radial_symbol": None, "radial_cut": CUT(x=210, y=120, w=110, h=60, side=1)}
    now, x, y, h = 20_000, 0, 0, 0
    res = _cut_twice(py, c, now, TaskInputs(sonar_mm=(0,) * 5, detections=cut), out)
    now += method001.CUT_WAIT_US
    drove = 0
    while res.wheels_mmps != (0, 0):
        now += 20_000
        x, y, h = _move(res, x, y, h)
        drove += res.wheels_mmps == (py.p.wander_mmps,) * 2
        echo = (0, 0, 300 if drove >= 3 else 0, 0, 0)  # something 0.3 m ahead after 60 mm
        res = _step_both(py, c, now, TaskInputs(x_mm=x, y_mm=y, heading_mrad=h, sonar_mm=echo,
                                                detections=cut), out, _frame000)
    assert drove == 3 and math.hypot(x, y) < 100 and py.ms.back_off[0] == "look"


def test_a_given_object_place_counts_as_found_in_c():
    """001 section II: P_i given, the C task starts with the object counted as found, as the
    Python's (machine.py graspable_seen); without it, not."""
    for with_place in (0, 1):
        rules = C.mg_task_method_find(b"001")
        p = FFI.new("mg_task_params_t *")
        rules.params(p)
        p.has_object_xy, p.object_xy_mm = with_place, [1500, 200]
        t = FFI.new("mg_task_t *")
        assert C.mg_task_init(t, rules, p, 0) == 0
        params = {"object_xy_mm": (1500, 200)} if with_place else {}
        assert t.graspable_seen == Task("001", params=params).graspable_seen == bool(with_place)
