"""Method 000 in C (hostc/task_method000.c, the path approach of hostc/task_approach.c, ADJUST's
reading of the radial symbol in hostc/task_adjust.c) against the Python (host/task/method000.py,
approach.py, adjust.py): the same calls with the same inputs give the same transitions, wheel
commands, arm targets, estimates, paths and charged planning time, hook by hook and step by step;
hypothesis-made sequences, and the calls the Python task made in the shipped scenario
paper000-exp1 replayed.

The C's 000 planner is the method state's ``mg_planner000_fn``: the board's
(``mg_method000_plan000``, plan000.c) is held to Method000.plan and plans the replay; the step
by step test gives both tasks the same drawn plans and checks the requests."""

from __future__ import annotations

import json
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from test_hostc_arm_kinematics import _assert_same_ik
from test_hostc_control import trajectories
from test_hostc_planning import _params000_c
from test_hostc_task import recorder, replay_remember
from test_hostc_task_states import (
    _c_inputs,
    _detail,
    _recorded_steps,
    _step_both,
    enter_state,
    steps_and_fresh,
)

from mobigrasp import hostc
from mobigrasp.host.app import jsonable
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.control.fuzzy import FuzzyParams
from mobigrasp.host.control.path_follow import PathFollower
from mobigrasp.host.kinematics import PAPER_000
from mobigrasp.host.planning.bezier000 import Params000
from mobigrasp.host.search import SearchParams
from mobigrasp.host.task import Task, TaskInputs, machine
from mobigrasp.host.task.adjust import ADJUST, AdjustState
from mobigrasp.host.task.approach import PATH, ApproachStates
from mobigrasp.host.task.method import Method
from mobigrasp.host.task.method000 import Method000, plan_follower
from mobigrasp.host.task.sense import CAMERA_000
from mobigrasp.host.vision import registry

FFI, C = hostc.lib()
SETTINGS = examples(100)
ANGLE = st.integers(-4000, 4000)
NEAR = st.integers(-3000, 3000)
WHY_BYTES = len(FFI.new("mg_task_event_t *").why)
RADIAL = registry.row("radial_symbol")
PLUS = registry.row("dual_plus")
PLAN_CB = "void(void *, const mg_plan000_request_t *, mg_trajectory_t *, mg_plan_outcome_t *)"


def _c_params(py: Task, c) -> None:
    """The Python task's parameters into the C's (the fields the C has)."""
    p = c.p
    for name, _ in FFI.typeof("mg_task_params_t").fields:
        if name == "timeouts_us":
            p.timeouts_us[0:C.MG_N_TASK_STATES] = [py.p.timeouts_us.get(s, -1)
                                                   for s in machine.STATES]
        elif name == "search":
            sp = SearchParams(**py.p.search)
            for f, _ in FFI.typeof("mg_search_params_t").fields:
                if f == "coarse_theta2_mrad":
                    p.search.n_coarse = len(sp.coarse_theta2_mrad)
                    p.search.coarse_theta2_mrad[0:p.search.n_coarse] = sp.coarse_theta2_mrad
                elif f != "n_coarse":
                    setattr(p.search, f, getattr(sp, f))
        elif name == "posture":
            pp = py.posture_params(0)
            p.posture.k_theta_q12[0:3] = list(pp.k_theta_q12)
            p.posture.margin_mode = ["printed", "limits"].index(pp.margin_mode)
            p.posture.max_step_mrad = 0
        elif name == "object_xy_mm":
            p.has_object_xy = len(py.p.object_xy_mm) == 2
            p.object_xy_mm = py.p.object_xy_mm or (0, 0)
        elif name not in ("fuzzy", "has_object_xy"):
            setattr(p, name, getattr(py.p, name))


def _c_task(py: Task | None = None, start_us: int = 0, method: str = "000"):
    rules = C.mg_task_method_find(method.encode())
    p = FFI.new("mg_task_params_t *")
    rules.params(p)
    t = FFI.new("mg_task_t *")
    assert C.mg_task_init(t, rules, p, start_us) == 0
    if py is not None:
        _c_params(py, t)
    return t


def _events(t) -> list:
    assert t.events_lost == 0
    return [machine.TaskEvent(e.t_us, machine.STATES[getattr(e, "from")], machine.STATES[e.to],
                              FFI.string(e.why).decode())
            for e in t.events[0:t.n_events]]


def _inputs(xyhv: tuple, sonar_mm: tuple = ()):
    inp = FFI.new("mg_task_inputs_t *", dict(zip(("x_mm", "y_mm", "heading_mrad", "v_mmps"),
                                                 xyhv, strict=True)))
    inp.n_sonar = len(sonar_mm)
    inp.sonar_mm[0:len(sonar_mm)] = list(sonar_mm)
    return inp


def _sighting(row, det, f_px: int = CAMERA_000.f_px):
    """What a detector's glue gives the C of a result: its pixel and depth (none: depth 0)."""
    if det is None:
        return FFI.NULL
    return FFI.new("mg_sighting_t *", row.sighting_fn()(det, f_px) or (0, 0, 0))


def _plus_seen(det):
    """What the dual "+"'s glue gives the C of a result: its sighting, both "+" and dist_mm
    (none: NULL)."""
    if det is None:
        return FFI.NULL
    return FFI.new("mg_plus_seen_t *", {
        "sighting": PLUS.sighting_fn()(det, CAMERA_000.f_px) or (0, 0, 0),
        "uv_q4": [det.u1_q4, det.v1_q4, det.u2_q4, det.v2_q4], "dist_mm": det.dist_mm})


def _path_py(t) -> tuple:
    """The path approach's state on the Python task."""
    f, j = t.follower, t.plan_job
    return (None if f is None else (f.start_us, f.v_limit_mm_s, f.steps, f.traj.t_us),
            None if j is None else (j.remaining_us, j.follower is not None,
                                    j.detail is not None),
            t.plan_obj, t.plan_us, t.plan_attempts, t.counters["plans"])


def _path_c(c) -> tuple:
    ps = c.path
    f = ps.follower
    return (None if not ps.has_follower else (f.start_us, f.v_limit_mm_s, f.steps,
                                              tuple(ps.traj.t_us[0:ps.traj.n])),
            None if not ps.has_job else (ps.job_remaining_us, bool(ps.has_next),
                                         bool(ps.job_has_detail)),
            tuple(ps.plan_obj_mm) if ps.has_plan_obj else None, ps.plan_us, ps.plan_attempts,
            ps.plans)


def _fill_plan(traj, o, plan: tuple) -> None:
    """A recorded plan (path table or None, its wheel limit, time, reason) into the C's."""
    table, v_limit, time_us, reason = plan
    o.has_path, o.v_limit_mm_s, o.time_us = table is not None, v_limit, time_us
    o.reason = reason.encode()[:C.MG_PLAN_REASON - 1]
    if table is not None:
        traj.n = len(table.t_us)
        for name in ("t_us", "x_um", "y_um", "heading_mrad", "v_mm_s", "w_mrad_s"):
            getattr(traj, name)[0:traj.n] = getattr(table, name)


def _request_c(req) -> tuple:
    return (req.now_us, req.x_mm, req.y_mm, req.heading_mrad, req.v_mmps, tuple(req.obj_mm),
            req.standoff_mm)


class Planner:
    """The plans of a run, given in turn to the Python task (Method000.plan) and, for the same
    requests, to the C's (its mg_planner000_fn); the requests of both kept."""

    def __init__(self, plans: list[tuple]) -> None:
        self.plans, self.py_at, self.c_at = plans, 0, 0
        self.py_requests: list[tuple] = []
        self.c_requests: list[tuple] = []
        self.callback = FFI.callback(PLAN_CB, self._c_plan)

    def py_plan(self, t, now, inp):
        self.py_requests.append((now, inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps,
                                 tuple(t.obj), t.p.approach_standoff_mm))
        table, v_limit, time_us, reason = self.plans[self.py_at % len(self.plans)]
        self.py_at += 1
        follower = None if table is None else PathFollower(table, now, v_limit)
        return follower, OpCounts(alu=time_us * C.MG_TASK_PLAN_CYCLES_PER_US), {"reason": reason}

    def _c_plan(self, ctx, req, traj, o) -> None:
        self.c_requests.append(_request_c(req))
        _fill_plan(traj, o, self.plans[self.c_at % len(self.plans)])
        self.c_at += 1


def _board_planner(p) -> tuple:
    """The board's 000 planner (mg_method000_plan000) on the task parameters ``p``, as
    Method000.plan makes its Params000: (function, ctx)."""
    pp = Params000(**{"standoff_m": p.approach_standoff_mm / 1000, **p.planner})
    ctx = FFI.new("mg_plan000_ctx_t *")
    ctx.params = _params000_c(pp)[0]
    ctx.v_limit_mm_s = int(round(pp.v_max * 1000))
    return FFI.addressof(C, "mg_method000_plan000"), ctx


@examples(60)
@given(st.integers(0, 10**9), st.tuples(NEAR, NEAR, st.integers(-3142, 3141),
                                        st.integers(-300, 300)),
       st.tuples(st.integers(-4000, 4000), st.integers(-4000, 4000)), st.integers(0, 1500),
       st.fixed_dictionaries({}, optional={
           "v0": st.sampled_from([0.05, 0.12, 0.2]), "a_max": st.sampled_from([0.01, 0.04, 0.1]),
           "r_min": st.sampled_from([0.1, 0.3, 1.0]), "t_s": st.sampled_from([0.1, 0.3]),
           "k1": st.sampled_from([0.0, 0.5, 2.0])}))
def test_the_board_planner_of_000(now, xyhv, obj, standoff_mm, planner):
    """The board's planner behind mg_planner000_fn (plan000.c) gives what Method000.plan gives
    the task: the same reference table, wheel limit, modelled time and reason."""
    py = Task("000", params={"approach_standoff_mm": standoff_mm, "planner": planner})
    fn, ctx = _board_planner(py.p)
    req = FFI.new("mg_plan000_request_t *", (now, *xyhv, obj, standoff_mm))
    traj, o = FFI.new("mg_trajectory_t *"), FFI.new("mg_plan_outcome_t *")
    fn(ctx, req, traj, o)
    pp = Params000(**{"standoff_m": standoff_mm / 1000, **planner})
    follower, ops, detail = plan_follower(now, *xyhv, obj, pp)
    assert (FFI.string(o.reason).decode(), o.time_us, bool(o.has_path)) == (
        detail["reason"], ops.time_us(), follower is not None)
    if follower is not None:
        assert o.v_limit_mm_s == follower.v_limit_mm_s
        for name in ("t_us", "x_um", "y_um", "heading_mrad", "v_mm_s", "w_mrad_s"):
            assert list(getattr(traj, name))[:traj.n] == list(getattr(follower.traj, name))


@pytest.mark.parametrize("method", ["000", "001", "002"])
def test_params_are_those_of_the_python_task(method):
    """Every field of the C's parameters (the defaults, TaskParams(), with the method's own),
    the method's arm and camera."""
    py, c = Task(method), _c_task(method=method)
    for name, _ in FFI.typeof("mg_task_params_t").fields:
        if name == "timeouts_us":
            assert list(c.p.timeouts_us) == [py.p.timeouts_us.get(s, -1) for s in machine.STATES]
        elif name == "search":
            sp = SearchParams(**py.p.search)
            got = {f: getattr(c.p.search, f) for f, _ in FFI.typeof("mg_search_params_t").fields
                   if f not in ("n_coarse", "coarse_theta2_mrad")}
            assert got == {f: getattr(sp, f) for f in got}
            assert list(c.p.search.coarse_theta2_mrad)[:c.p.search.n_coarse] \
                == list(sp.coarse_theta2_mrad)
        elif name == "posture":
            pp = py.posture_params(0)
            assert (tuple(c.p.posture.k_theta_q12), c.p.posture.margin_mode) == (
                pp.k_theta_q12, ["printed", "limits"].index(pp.margin_mode))
        elif name == "fuzzy":
            fz = FuzzyParams(**py.p.fuzzy)
            assert {f: getattr(c.p.fuzzy, f) for f, _ in FFI.typeof("mg_fuzzy_params_t").fields} \
                == {f: getattr(fz, f) for f, _ in FFI.typeof("mg_fuzzy_params_t").fields}
        elif name == "object_xy_mm":
            assert (tuple(c.p.object_xy_mm) if c.p.has_object_xy else ()) == py.p.object_xy_mm
        elif name != "has_object_xy":
            assert getattr(c.p, name) == getattr(py.p, name), name
    assert (c.geom.l1_mm_q4, c.geom.l2_mm_q4, c.geom.l3_mm_q4) == (
        py.geom.l1_mm_q4, py.geom.l2_mm_q4, py.geom.l3_mm_q4)
    assert (c.cam.f_px, c.cam.u0_px, c.cam.v0_px) == (py.cam.f_px, py.cam.u0_px, py.cam.v0_px)


@pytest.mark.parametrize("method", ["000", "001"])
def test_the_rows_of_000_and_001(method):
    """The method table's rows: ADJUST's detector, the grasp's pitch, the look heights."""
    py, c = Task(method), _c_task(method=method)
    rules = C.mg_task_method_find(method.encode())
    r = py.rules
    assert FFI.string(rules.adjust_detector).decode() == r.adjust_detector
    assert rules.adjust_is_object == (r.adjust_detector in r.object_detectors)
    assert "radial_symbol" in r.object_detectors  # the C's radial sighting is the object's
    assert rules.grasp_alpha_mrad == r.grasp_alpha_mrad
    assert (rules.adjust_keeps_posture, rules.plus_on_top) == (r.adjust_keeps_posture,
                                                               r.plus_on_top)
    assert C.mg_method000_lowers_hover() == r.lowers_hover()
    for top in (0, 1):
        assert rules.look_height_mm(FFI.addressof(c, "p"), top) == r.look_height_mm(py.p, top)
    # 000's searches after a loss near the object, or Method's none (001's: the usual search,
    # the rough position when no spoke is seen)
    own = type(r).grasp_lost is not Method.grasp_lost
    assert own == (type(r).lost_search is not Method.lost_search) == (method == "000")
    assert (rules.grasp_lost != FFI.NULL, rules.lost_search != FFI.NULL) == (own, own)
    assert rules.guard_wheels != FFI.NULL
    # SEARCH: the symbol cut by the frame read where the symbol is not, and the move off it
    assert rules.search_back_off != FFI.NULL
    names = [FFI.string(C.mg_detector_names[i]).decode() for i in range(C.MG_N_DETECTORS)]
    bits = C.mg_task_detectors_needed(c)
    assert [n for i, n in enumerate(names) if bits >> i & 1] == py.detectors_needed()
    assert {names[i]: names[C.mg_task_detector_fallback(c, i)] for i in range(len(names))
            if C.mg_task_detector_fallback(c, i) >= 0} == py.detector_fallbacks()


@SETTINGS
@given(st.integers(0, 400), st.integers(0, 400), st.booleans(), st.integers(1, 400),
       st.integers(0, 100), st.integers(0, 10**7))
def test_the_hooks_of_the_close_approach(top, grasp_h, look_top, grasp_r, tol, now):
    """The look height of eq. (10), ADJUST's goal, speed and stop rule."""
    py = Task("000", params={"object_top_mm": top, "grasp_height_mm": grasp_h,
                             "grasp_r_mm": grasp_r, "grasp_r_tol_mm": tol})
    c = _c_task(py)
    rules = Method000()
    assert C.mg_method000_look_height_mm(FFI.addressof(c, "p"), look_top) \
        == rules.look_height_mm(py.p, look_top)
    goal, t = FFI.new("int32_t *"), FFI.new("int32_t *")
    C.mg_method000_adjust_goal_mm(c, goal, t)
    assert (goal[0], t[0]) == rules.adjust_goal_mm(py)
    assert C.mg_method000_adjust_vmax_mmps(FFI.addressof(c, "p")) == rules.adjust_vmax_mmps(py.p)
    assert C.mg_method000_adjust_done(c, now, FFI.NULL, grasp_r) \
        == rules.adjust_done(py, now, None, grasp_r)


@SETTINGS
@given(st.tuples(st.integers(-400 * 16, 400 * 16), st.integers(-400 * 16, 400 * 16),
                 st.integers(-300 * 16, 300 * 16)))
def test_the_grasp_ik_of_000(target):
    """The gripper down, eq. (11) of 000."""
    pose, detail = FFI.new("mg_arm_pose_t *"), FFI.new("int64_t *")
    code = C.mg_method000_grasp_ik(FFI.addressof(_c_task(), "geom"), target, pose, detail)
    _assert_same_ik(code, pose, detail[0], Method000().grasp_ik(PAPER_000, target))


@SETTINGS
@given(st.lists(st.tuples(st.integers(1, 10**7), st.integers(0, 10**7)), max_size=4))
def test_the_grasp_lost_of_000(calls):
    """No spoke at the hover: the first time a search (LOST, lost in PRECISE_GRASP), after
    that the grasp goes on."""
    py, c = Task("000"), _c_task()
    py.go(0, "PRECISE_GRASP", "test")
    C.mg_task_go(c, 0, C.MG_PRECISE_GRASP, b"test")
    now = 0
    for dt, waited in calls:
        now += dt
        py._events, c.n_events = [], 0
        assert C.mg_method000_grasp_lost(c, now, waited) == Method000().grasp_lost(py, now,
                                                                                    waited)
        assert _events(c) == py._events
        assert FFI.cast("mg_state000_t *", c.ms.bytes).grasp_searches == py.ms.grasp_searches
        assert (machine.STATES[c.lost_in] if c.lost_in >= 0 else None) == py.lost_in


SEARCH_PARAMS = st.builds(
    lambda lo, span, th3, th4, dense: SearchParams(
        theta2_min_mrad=lo, theta2_max_mrad=lo + span, theta3_mrad=th3, theta4_mrad=th4,
        dense_cycles=dense),
    st.integers(-3000, -100), st.integers(10, 2000), ANGLE, ANGLE, st.integers(0, 3))


@SETTINGS
@given(st.tuples(*[ANGLE] * 4), SEARCH_PARAMS)
def test_the_search_after_a_loss(joints, sp):
    """Fig. 5 from where the camera looked: theta2s keeps its pitch in the search posture, at
    least one dense cycle, the waist where it was."""
    py, c = Task("000"), _c_task()
    py.arm[2:6] = c.arm[2:6] = list(joints)
    csp = FFI.new("mg_search_params_t *")
    for name in ("theta2_min_mrad", "theta2_max_mrad", "theta3_mrad", "theta4_mrad",
                 "dense_cycles"):
        setattr(csp, name, getattr(sp, name))
    th2s, th5s = FFI.new("int32_t *"), FFI.new("int32_t *")
    C.mg_method000_lost_search(c, csp, th2s, th5s)
    new, th2, th5 = Method000().lost_search(py, sp, "ADJUST")
    assert (csp.dense_cycles, th2s[0], th5s[0]) == (new.dense_cycles, th2, th5)


def _radial(u, v, depth_mm):
    return RADIAL.result_type()(u_q4=u, v_q4=v, diameter_q4=0, y_oc_mm=depth_mm, x_oc_mm=0,
                                z_oc_mm=0)


RADIALS_SEEN = st.builds(_radial, st.integers(0, 320 * 16), st.integers(0, 240 * 16),
                         st.integers(-50, 3000))
RADIALS = st.none() | RADIALS_SEEN


@SETTINGS
@given(st.lists(st.tuples(st.integers(1, 300_000), st.tuples(*[ANGLE] * 4), RADIALS,
                          st.tuples(NEAR, NEAR, st.integers(-3142, 3141)),
                          st.integers(0, 300_000)), max_size=20))
def test_the_search_sighting_of_000(steps):
    """SEARCH's radial symbol: the estimate from its pixel and depth with the arm and base of
    its capture, unusable ones counted, the transition's reason."""
    py, c = Task("000"), _c_task()
    rules, now = Method000(), 0
    why = FFI.new("char[]", WHY_BYTES)
    for dt, joints, det, xyh, trust_back in steps:
        now += dt
        py.set_arm(now, *joints)
        C.mg_task_set_arm(c, now, *joints, 0, 0)
        py.trust_from_us = c.trust_from_us = now - trust_back
        inp = TaskInputs(x_mm=xyh[0], y_mm=xyh[1], heading_mrad=xyh[2])
        if det is not None:
            seen = rules.found(py, now, inp, "radial_symbol", det)
            assert C.mg_method000_found(c, now, _inputs((*xyh, 0)), _sighting(RADIAL, det)) \
                == seen
        assert (tuple(c.obj_mm) if c.has_obj else None, c.obj_seen_us) == (py.obj,
                                                                         py.obj_seen_us)
        assert (c.bad_detections, c.graspable_seen, c.object_sighted) == (
            py.counters["bad_detections"], py.graspable_seen, py.object_sighted)
        if py.obj is not None:
            C.mg_method000_found_why(c, why, WHY_BYTES)
            assert FFI.string(why).decode() == rules.found_why(py)
        py.remember(now, inp)
        C.mg_task_remember(c, now, *xyh)


def _facing(obj: tuple[int, int], heading_mrad: int, ahead_mm: int) -> tuple[int, int, int]:
    """The base pose (x_mm, y_mm, heading_mrad) with the object ``ahead_mm`` in front of its
    waist (100 mm ahead of the axle)."""
    h = heading_mrad / 1000
    return (obj[0] - round((100 + ahead_mm) * math.cos(h)),
            obj[1] - round((100 + ahead_mm) * math.sin(h)), heading_mrad)


POSES = st.tuples(NEAR, NEAR, st.integers(-3142, 3141)) | st.tuples(
    st.just("facing"), st.integers(-3142, 3141), st.integers(60, 400))


def _pose(obj: tuple[int, int], pose: tuple) -> tuple[int, int, int]:
    return _facing(obj, *pose[1:]) if pose[0] == "facing" else pose


REASONS = ["already within standoff of the object", "speed: 14 of 14 candidates",
           "accel: 9, radius: 5", "budget"]
PLANS = st.lists(st.one_of(
    st.tuples(trajectories(), st.integers(0, 400), st.integers(0, 40_000),
              st.sampled_from(["ok"])),
    st.tuples(st.none(), st.integers(0, 400), st.integers(0, 40_000), st.sampled_from(REASONS))),
    min_size=1, max_size=6)


def path_step(py, c, now: int, xyhv: tuple, sonar_mm: tuple, det, c_step) -> TaskInputs:
    """One step of the path approach on both tasks, the C's by ``c_step``, with the pose and
    speed ``xyhv``, the sonar ranges and this frame's radial symbol ``det``: the same
    transitions, wheels, arm targets, estimate, path and charged planning time. The Python's
    inputs."""
    py._events, py._ops, c.n_events = [], OpCounts(), 0
    FFI.memmove(FFI.addressof(c.path, "ops"), FFI.new("mg_ops_t *"), FFI.sizeof("mg_ops_t"))
    inp = TaskInputs(x_mm=xyhv[0], y_mm=xyhv[1], heading_mrad=xyhv[2], v_mmps=xyhv[3],
                     sonar_mm=sonar_mm)
    PATH.follow_path(py, now, inp, {} if det is None else {"radial_symbol": det})
    c_step(c, now, _inputs(xyhv, sonar_mm), _sighting(RADIAL, det))
    assert _events(c) == py._events
    assert (tuple(c.wheels), list(c.arm), c.move_done_us) == (py.wheels, py.arm,
                                                              py.move_done_us)
    assert (tuple(c.obj_mm), c.obj_seen_us, c.bad_detections) == (
        py.obj, py.obj_seen_us, py.counters["bad_detections"])
    assert _path_c(c) == _path_py(py)
    assert hostc.ops_tuple(c.path.ops) == py._ops.as_tuple()
    if c.has_failure:
        assert FFI.string(c.failure).decode() == py.failure
    return inp


def start_approach(py, c, obj: tuple[int, int]) -> None:
    """Both tasks into APPROACH with the object estimate ``obj`` (the entry action run)."""
    py.obj = obj
    c.has_obj, c.obj_mm = 1, obj
    py.go(0, "APPROACH", "test")
    C.mg_task_go(c, 0, C.MG_APPROACH, b"test")
    ApproachStates().enter_APPROACH(py, 0, TaskInputs())
    C.mg_method000_enter_approach(c)


@SETTINGS
@given(PLANS, st.tuples(NEAR, NEAR), st.integers(1, 4), st.integers(0, 2000),
       st.integers(0, 400), st.lists(st.tuples(
           st.sampled_from([20_000, 40_000, 500_000]) | st.integers(1, 3_000_000),
           POSES, st.integers(-300, 300), RADIALS, st.none() | st.tuples(NEAR, NEAR)),
           max_size=40))
def test_the_path_approach_of_000(plans, obj, attempts, direct_mm, shift_mm, steps):
    """APPROACH of 000 step by step on the same plans: the radial symbol's estimate, the plan's
    slices charged while the old path is followed or the base stands, the path taken in the
    step of the last slice, replanning when the estimate moved, the failed plans (already
    there, facing the object, the direct approach, FAILED) and ADJUST at the path's end."""
    py = Task("000", params={"max_plan_attempts": attempts, "direct_max_mm": direct_mm,
                             "replan_shift_mm": shift_mm})
    c = _c_task(py)
    planner = Planner(plans)
    C.mg_method000_set_planner(c, planner.callback, FFI.NULL)
    start_approach(py, c, obj)
    now = 0
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Method000, "plan", planner.py_plan)
        for dt, pose, v_mmps, det, moved_to in steps:
            now += dt
            xyhv = (*_pose(py.obj, pose), v_mmps)
            if moved_to is not None:  # the estimate moved (a sighting elsewhere)
                py.obj = moved_to
                c.obj_mm = moved_to
            inp = path_step(py, c, now, xyhv, (), det, C.mg_method000_approach)
            assert planner.c_requests == planner.py_requests
            if py.state != "APPROACH":
                break
            py.remember(now, inp)
            C.mg_task_remember(c, now, *xyhv[:3])


def _plus(u1, v1, u2, v2, dist_mm):
    return PLUS.result_type()(u1_q4=u1, v1_q4=v1, u2_q4=u2, v2_q4=v2, d_pixel_q4=0, d_eff_q4=0,
                              dist_mm=dist_mm, dist_raw_mm=0, x_oc_mm=0, y_oc_mm=0, z_oc_mm=0)


PX_U, PX_V = st.integers(0, 320 * 16), st.integers(0, 240 * 16)
PLUSES_SEEN = st.builds(_plus, PX_U, PX_V, PX_U, PX_V, st.integers(-50, 1500))
PLUSES = st.none() | PLUSES_SEEN


@SETTINGS
@given(st.tuples(NEAR, NEAR), st.tuples(*[ANGLE] * 4),
       st.lists(st.tuples(st.sampled_from([20_000, 500_000, 1_600_000]) | st.integers(1, 10**6),
                          PLUSES, RADIALS, POSES), max_size=30),
       st.sampled_from([(4096, 0, 0), (4096, 2048, 1024), (0, 4096, 4096)]))
def test_the_adjust_of_000(obj, joints, steps, k_theta_q12):
    """ADJUST of 000 step by step from the posture it enters with: the dual "+", or the radial
    symbol when no "+" were seen, updates the estimate; the close approach to grasp_r_mm, the
    posture adjustment by eq. (10) with the gains given, LOST when unseen, ROUGH_GRASP."""
    py = Task("000", {"posture": {"k_theta_q12": k_theta_q12}})
    c = _c_task(py)
    py.arm[2:6] = c.arm[2:6] = list(joints)
    py.obj = obj
    c.has_obj, c.obj_mm = 1, obj
    py.go(0, "ADJUST", "test")
    C.mg_task_go(c, 0, C.MG_ADJUST, b"test")
    ADJUST.enter_ADJUST(py, 0, TaskInputs())
    C.mg_task_enter_adjust(c, 0)
    now = 0
    for dt, plus, radial, pose in steps:
        now += dt
        xyh = _pose(py.obj, pose)
        py._events, c.n_events = [], 0
        dets = {k: v for k, v in (("dual_plus", plus), ("radial_symbol", radial))
                if v is not None}
        inp = TaskInputs(x_mm=xyh[0], y_mm=xyh[1], heading_mrad=xyh[2])
        ADJUST.do_ADJUST(py, now, inp, dets)
        C.mg_task_do_adjust(c, now, _inputs((*xyh, 0)), _plus_seen(plus),
                            _sighting(RADIAL, radial))
        assert _events(c) == py._events
        assert (tuple(c.wheels), list(c.arm), c.move_done_us, c.trust_from_us) == (
            py.wheels, py.arm, py.move_done_us, py.trust_from_us)
        assert (tuple(c.obj_mm), c.obj_seen_us, c.bad_detections) == (
            py.obj, py.obj_seen_us, py.counters["bad_detections"])
        assert machine.STATES[c.state] == py.state
        if py.state != "ADJUST":
            break
        py.remember(now, inp)
        C.mg_task_remember(c, now, *xyh)


def _task_state(t) -> tuple:
    """What a state's step reads and changes of the shared state."""
    return (list(t.arm), t.move_done_us, t.obj, t.obj_seen_us, t.trust_from_us,
            t.counters["bad_detections"], t.entered_us, t.object_sighted)


def _load(c, state: tuple) -> None:
    arm, done, obj, seen, trust, bad, entered, sighted = state
    c.arm[0:6] = arm
    c.move_done_us, c.obj_seen_us, c.trust_from_us, c.bad_detections = done, seen, trust, bad
    c.has_obj, c.obj_mm = obj is not None, obj or (0, 0)
    c.entered_us, c.object_sighted = entered, sighted


def _c_state(c) -> tuple:
    return (list(c.arm), c.move_done_us, tuple(c.obj_mm) if c.has_obj else None, c.obj_seen_us,
            c.trust_from_us, c.bad_detections, c.entered_us, bool(c.object_sighted))


def record_path_task(mp, calls: list):
    """The calls of a path method's task (000, 001): its parameters, SEARCH's sighting,
    APPROACH's and ADJUST's entries and steps, and the history they read; the recorder, for
    the method's own (its planner's calls)."""
    wrap = recorder(mp, calls)
    wrap(machine.Task, "remember",
         lambda t, now, inp: ("remember", now, (inp.x_mm, inp.y_mm, inp.heading_mrad),
                              list(t.arm)),
         lambda res, t, *a: (len(t.arm_hist), len(t.pose_hist)))
    wrap(Method000, "found",
         lambda rules, t, now, inp, name, det: (
             "found", now, (inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps), det,
             _task_state(t)),
         lambda res, rules, t, *a: (res, _task_state(t), t.graspable_seen,
                                    rules.found_why(t) if res else None), quiet=True)
    wrap(Method000, "enter_approach", lambda rules, t, now, inp: ("enter_approach", t.p),
         lambda res, rules, t, *a: (_path_py(t),))

    def approach_before(paths, t, now, inp, dets):
        return ("approach", now, (inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps),
                tuple(inp.sonar_mm), dets.get("radial_symbol"), _task_state(t), t.state,
                _path_py(t), len(t._events), t._ops.as_tuple())
    wrap(ApproachStates, "follow_path", approach_before,
         lambda res, paths, t, *a: (list(t._events), t.wheels, _task_state(t), t.state,
                                    _path_py(t), t._ops.as_tuple()))
    wrap(AdjustState, "enter_ADJUST",
         lambda adj, t, now, inp: ("enter_adjust", now, _task_state(t)),
         lambda res, adj, t, *a: (_task_state(t),))
    wrap(AdjustState, "do_ADJUST",
         lambda adj, t, now, inp, dets: (
             "adjust", now, (inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps),
             dets.get("dual_plus"), dets.get("radial_symbol"), _task_state(t), len(t._events)),
         lambda res, adj, t, *a: (list(t._events), t.wheels, _task_state(t), t.state))
    # the machine's tables hold ADJUST's methods bound at import: through the class now
    mp.setitem(machine.ENTRY, "ADJUST", lambda *a: ADJUST.enter_ADJUST(*a))
    mp.setitem(machine.STEP, "ADJUST", lambda *a: ADJUST.do_ADJUST(*a))
    return wrap


def record000(mp, calls: list) -> None:
    """000's task's calls, and the plans."""
    wrap = record_path_task(mp, calls)
    wrap(Method000, "plan",
         lambda rules, t, now, inp: ("plan", (now, inp.x_mm, inp.y_mm, inp.heading_mrad,
                                              inp.v_mmps, tuple(t.obj),
                                              t.p.approach_standoff_mm)),
         lambda res, *a: ((None if res[0] is None else res[0].traj,
                           0 if res[0] is None else res[0].v_limit_mm_s, res[1].time_us(),
                           res[2]["reason"]),), quiet=True)


def replay_path_task(calls: list, method: str, setup, c_approach) -> dict:
    """Each recorded call (record_path_task) on a C task of the method carrying its own
    history and path, with the shared state the Python call read; what it gave compared.
    ``setup(c)`` gives the C task the planner's recorded outcomes; ``c_approach`` is its
    APPROACH step. The count of calls of each kind."""
    py = Task(method)
    py.p = next(r[1] for r in calls if r[0] == "enter_approach")
    c = _c_task(py, method=method)
    setup(c)
    why = FFI.new("char[]", WHY_BYTES)
    counts: dict = {}
    for rec in calls:
        kind = rec[0]
        counts[kind] = counts.get(kind, 0) + 1
        if kind == "remember":
            replay_remember(c, rec)
        elif kind == "found":
            _, now, xyhv, det, pre, res, post, graspable, found_why = rec
            _load(c, pre)
            assert C.mg_method000_found(c, now, _inputs(xyhv), _sighting(RADIAL, det)) == res
            assert (_c_state(c), c.graspable_seen) == (post, graspable), rec
            if res:
                C.mg_method000_found_why(c, why, WHY_BYTES)
                assert FFI.string(why).decode() == found_why
        elif kind == "enter_approach":
            C.mg_method000_enter_approach(c)
            assert _path_c(c) == rec[2], rec
        elif kind == "approach":
            (_, now, xyhv, sonar, det, pre, state, path, n_events, ops, events, wheels, post,
             post_state, post_path, post_ops) = rec
            _load(c, pre)
            c.state, c.n_events = machine.STATES.index(state), 0
            FFI.memmove(FFI.addressof(c.path, "ops"), FFI.new("mg_ops_t *"),
                        FFI.sizeof("mg_ops_t"))
            assert _path_c(c) == path, rec  # the C's path carried from its last step
            c_approach(c, now, _inputs(xyhv, sonar), _sighting(RADIAL, det))
            assert _events(c) == events[n_events:], rec
            assert (tuple(c.wheels), _c_state(c), machine.STATES[c.state]) == (
                wheels, post, post_state), rec
            assert _path_c(c) == post_path, rec
            assert hostc.ops_tuple(c.path.ops) == tuple(b - a for a, b in zip(
                ops, post_ops, strict=True)), rec
        elif kind == "enter_adjust":
            _, now, pre, post = rec
            _load(c, pre)
            C.mg_task_enter_adjust(c, now)
            assert _c_state(c) == post, rec
        elif kind == "adjust":
            _, now, xyhv, plus, radial, pre, n_events, events, wheels, post, state = rec
            _load(c, pre)
            c.state, c.n_events = C.MG_ADJUST, 0
            C.mg_task_do_adjust(c, now, _inputs(xyhv), _plus_seen(plus),
                                _sighting(RADIAL, radial))
            assert _events(c) == events[n_events:], rec
            assert (tuple(c.wheels), _c_state(c), machine.STATES[c.state]) == (
                wheels, post, state), rec
    assert c.hist_overflow == 0 and c.events_lost == 0
    return counts


def _replay000(calls: list) -> dict:
    """000's calls replayed, the C planning with the board's planner (plan000.c) on the run's
    parameters."""
    fn, ctx = _board_planner(next(r[1] for r in calls if r[0] == "enter_approach"))
    return replay_path_task(calls, "000", lambda c: C.mg_method000_set_planner(c, fn, ctx),
                            C.mg_method000_approach)


def test_replay_of_paper000_exp1(shared_recording):
    """The calls the Python task made in paper000-exp1 replayed on the C task with the same
    inputs: SEARCH's sighting, APPROACH's path (planned by the board's planner, its plan
    charged, followed to its end) and ADJUST step by step give the same outputs, call by
    call."""
    calls = shared_recording("paper000-exp1", "calls")
    counts = _replay000(calls)
    assert counts.get("approach", 0) > 20 and counts.get("adjust", 0) > 5, counts
    assert counts.get("plan", 0) >= 1 and counts.get("found", 0) >= 1, counts
    # the plan's time charged in the step that made it (its slices: test_the_path_approach_of_000)
    assert any(r[0] == "approach" and r[15][2] > r[9][2] for r in calls)
    ended = [r for r in calls if r[0] == "approach" and r[10][r[8]:]]
    assert [e.to_state for e in ended[-1][10][ended[-1][8]:]] == ["ADJUST"]
    stopped = [r for r in calls if r[0] == "adjust" and r[7][r[6]:]]
    assert [e.to_state for e in stopped[-1][7][stopped[-1][6]:]] == ["ROUGH_GRASP"]


def test_a_method_without_a_path_stands():
    """The path approach of a method without path hooks (002's row) stops the base."""
    c = _c_task(method="002")
    assert C.mg_task_method_find(b"002").path == FFI.NULL
    c.wheels = (50, 60)
    C.mg_task_follow_path(c, 20_000, _inputs((0, 0, 0, 0)), FFI.NULL)
    assert tuple(c.wheels) == (0, 0) and c.path.plans == 0 and c.n_events == 0


def words000(name: str, res) -> list[int]:
    """A 000 detector's result as its C kernel's out words (hostc/kernels.h), the held fill's
    as hostc/app_factory.h lays them out."""
    if name == "radial_symbol":
        return [res.u_q4, res.v_q4, res.diameter_q4, res.y_oc_mm, res.x_oc_mm, res.z_oc_mm]
    if name == "dual_plus":
        return [res.u1_q4, res.v1_q4, res.u2_q4, res.v2_q4, res.d_pixel_q4, res.d_eff_q4,
                res.dist_mm, res.dist_raw_mm, res.x_oc_mm, res.y_oc_mm, res.z_oc_mm]
    if name == "spoke":
        pts = [v for p in res.points_q4 for v in p]
        return [res.u_c_q4, res.v_c_q4, res.slope_q12, res.angle_mrad, res.width_q4,
                len(res.points_q4), *pts, *[0] * (20 - len(pts))]
    if name == "radial_cut":
        return [res.x, res.y, res.w, res.h, res.side]
    return [*res.rgb, res.fill_permille]


def _frame000(dets: dict):
    """The detectors' results as the C task reads them: their out words through the C host's
    glue (hostc/app_factory.c mg_frame000_of)."""
    f = FFI.new("mg_frame000_t *")
    keep = [FFI.new("int32_t[]", words000(n, dets[n])) if dets.get(n) is not None else FFI.NULL
            for n in ("radial_symbol", "dual_plus", "spoke", "held_fill", "radial_cut")]
    C.mg_frame000_of(f, *keep)
    return f


def _c_step_inputs(inp: TaskInputs):
    """The C's step inputs of a Python TaskInputs, its frame through 000's glue."""
    return _c_inputs(inp, _frame000)


ENCODER = json.JSONEncoder(sort_keys=True, separators=(",", ":"))  # the trace's


def replay_steps000(steps: list, fresh: Task) -> list:
    """The recorded steps on the C task of 000 as the C program holds it (task_paper.h), its
    plans by the board's planner on the run's parameters: every output compared, the charged
    planning work too, and as the program reads them; the states passed through."""
    paper = FFI.new("mg_paper_task_t *")
    p = FFI.new("mg_task_params_t *")
    C.mg_task_method_find(b"000").params(p)
    assert C.mg_paper_task_init(paper, C.mg_task_method_find(b"000"), p, fresh.entered_us) == 0
    c = FFI.addressof(paper, "task")
    _c_params(fresh, c)
    _, ctx = _board_planner(fresh.p)
    C.mg_method000_set_board_planner(c, ctx)
    out, prog = FFI.new("mg_task_outputs_t *"), FFI.new("mg_task_output_t *")
    states: list = []
    for now, inp, res in steps:
        cin, _frame_kept = _c_step_inputs(inp)
        C.mg_task_step(c, now, cin, out)
        C.mg_paper_outputs(paper, out, prog)
        where = (now, res.state, res.detail)
        assert _events(c) == res.events, where
        assert (tuple(out.servo_mrad), tuple(out.wheels_mmps), out.gripper_permille,
                machine.STATES[out.state]) == (res.servo_mrad, res.wheels_mmps,
                                               res.gripper_permille, res.state), where
        want = {k: ENCODER.encode(jsonable(v)) for k, v in res.detail.items()}
        assert _detail(c) == want, where
        assert {FFI.string(d.key).decode(): FFI.string(d.json).decode()
                for d in prog.detail[0:prog.n_detail]} == want, where
        assert bool(prog.detail_has_plan) == (res.detail.get("plan") is not None), where
        assert hostc.ops_tuple(prog.ops) == res.ops.as_tuple(), where
        assert (tuple(c.obj_mm) if c.has_obj else None) == fresh_obj(res, c), where
        if not states or states[-1] != res.state:
            states.append(res.state)
    assert c.hist_overflow == 0 and paper.transitions_lost == 0
    return states


def fresh_obj(res, c):
    """The C's estimate (the Python's is compared through the outputs it drives)."""
    return tuple(c.obj_mm) if c.has_obj else None


def test_replay_of_paper000_exp1_whole(shared_recording):
    """Every step the Python task took in paper000-exp1, SEARCH to DONE, on the C task: the
    frames' results through the C glue, the plan by the board's planner and its trace
    detail, the hover over the nearer "+", the roll and the alignment on the spoke, the
    grasp check on the brown body."""
    steps, fresh = steps_and_fresh(shared_recording("paper000-exp1", "steps"))
    states = replay_steps000(steps, fresh)
    assert states[0] == "SEARCH" and states[-1] == "DONE"
    assert {"APPROACH", "ADJUST", "ROUGH_GRASP", "PRECISE_GRASP", "LIFT"} <= set(states)


SPOKE = registry.row("spoke").result_type()
HELD = registry.row("held_fill").result_type()
SPOKES = st.builds(lambda a, w, n: SPOKE(u_c_q4=160 * 16, v_c_q4=120 * 16,
                                         points_q4=((1, 2),) * n, slope_q12=0, angle_mrad=a,
                                         width_q4=w),
                   st.integers(-800, 800) | st.sampled_from([0, 10, -20, 40]),
                   st.integers(0, 60 * 16), st.integers(0, 10))
BROWN = st.builds(lambda r, g, b, p: HELD(rgb=(r, g, b), fill_permille=p),
                  st.integers(0, 255), st.integers(0, 255), st.integers(0, 255),
                  st.integers(900, 1000)) | st.just(HELD(rgb=(170, 130, 90), fill_permille=1000))
PAIRS = st.builds(lambda u, v, d, dist: _plus(u - d, v, u + d, v, dist), PX_U, PX_V,
                  st.integers(0, 60 * 16), st.integers(50, 800))
CUT = registry.row("radial_cut").result_type()
CUTS = st.builds(CUT, x=st.integers(0, 319), y=st.integers(0, 239), w=st.integers(1, 320),
                 h=st.integers(1, 240), side=st.sampled_from([-1, 0, 1]))
DETS000 = st.fixed_dictionaries({}, optional={
    "radial_symbol": RADIALS_SEEN, "dual_plus": PAIRS | PLUSES_SEEN, "spoke": SPOKES,
    "held_fill": BROWN, "radial_cut": CUTS})


def _paper_task000():
    """000's C task as the C program holds it (task_paper.h), with 000's parameters: (the
    holder, kept alive, and its task)."""
    paper = FFI.new("mg_paper_task_t *")
    p = FFI.new("mg_task_params_t *")
    C.mg_task_method_find(b"000").params(p)
    assert C.mg_paper_task_init(paper, C.mg_task_method_find(b"000"), p, 0) == 0
    return paper, FFI.addressof(paper, "task")


@examples(60)
@given(st.sampled_from([s for s in machine.STATES if s not in machine.TERMINAL]
                       + ["ROUGH_GRASP"] * 3),
       st.none() | st.tuples(st.integers(100, 900), st.integers(-300, 300))
       | st.tuples(st.integers(200, 260), st.integers(-30, 30)), st.booleans(),
       st.tuples(*[st.integers(-1500, 1500)] * 4),
       st.lists(st.tuples(st.sampled_from([20_000, 60_000, 500_000, 1_100_000]),
                          st.tuples(st.integers(-30, 30), st.integers(-30, 30),
                                    st.integers(-200, 200)),
                          st.booleans(), st.none() | DETS000), min_size=1, max_size=40))
def test_steps_of_000_from_every_state(state, obj, graspable, joints, steps):
    """From a state entered with an estimate (or none), steps with odometry that wanders, the
    gripper flag and frames of 000's detectors (the radial symbol, dual "+" pairs, spokes,
    the held fill): the same outputs, detail and charged planning work on both tasks."""
    py = Task("000")
    paper, c = _paper_task000()
    _, ctx = _board_planner(py.p)
    C.mg_method000_set_board_planner(c, ctx)
    # the states but SEARCH and LOST are entered with an estimate (by default in the reach)
    enter_state(py, c, state, obj, graspable, joints, (230, 10), ("SEARCH", "LOST"))
    out = FFI.new("mg_task_outputs_t *")
    now, x, y, h = 0, 0, 0, 0
    for dt, (dx, dy, dh), closed, dets in steps:
        now += dt
        x, y, h = x + dx, y + dy, h + dh
        inp = TaskInputs(x_mm=x, y_mm=y, heading_mrad=h, grasp_closed=closed,
                         detections=dets or {})
        res = _step_both(py, c, now, inp, out, _frame000)
        where = (now, py.state, res.detail)
        assert hostc.ops_tuple(c.path.ops) == res.ops.as_tuple(), where
        assert (tuple(map(tuple, c.plus_odom_mm)) if c.has_plus_odom else None) == (
            py.plus_odom), where
    assert c.hist_overflow == 0


@pytest.mark.slow
def test_replay_of_paper000_exp2_whole(tmp_path):
    """The same for paper000-exp2 (its longer search, 45.5 s simulated)."""
    steps, fresh = _recorded_steps(tmp_path, "paper000-exp2")
    assert replay_steps000(steps, fresh)[-1] == "DONE"


@examples(80)
@given(st.tuples(NEAR, NEAR, st.integers(-3142, 3141), st.integers(-300, 300)),
       st.tuples(st.integers(-4000, 4000), st.integers(-4000, 4000)), st.integers(0, 1500),
       st.fixed_dictionaries({}, optional={
           "v0": st.sampled_from([0.05, 0.12, 0.2]), "a_max": st.sampled_from([0.01, 0.04]),
           "r_min": st.sampled_from([0.1, 1.0]), "t_s": st.sampled_from([0.1, 0.3])}))
def test_the_plan_s_trace_detail(xyhv, obj, standoff_mm, planner):
    """The plan's detail in the trace (method000.py plan_follower): the candidates' and the
    chosen curve's control points in m and s printed as Python prints the floats, the
    counts, the reason and the plan's modelled time."""
    py = Task("000", params={"approach_standoff_mm": standoff_mm, "planner": planner})
    c = _c_task(py)
    _, ctx = _board_planner(py.p)
    C.mg_method000_set_board_planner(c, ctx)
    start_approach(py, c, obj)
    c.n_notes = 0
    C.mg_method000_approach(c, 20_000, _inputs(xyhv), FFI.NULL)
    pp = Params000(**{"standoff_m": standoff_mm / 1000, **planner})
    _, _, detail = plan_follower(20_000, *xyhv, obj, pp)
    assert _detail(c)["plan"] == ENCODER.encode(jsonable(detail))


def _paper_c000(py: Task):
    """The C task of 000 as the C program holds it, with the board's planner."""
    paper = FFI.new("mg_paper_task_t *")
    p = FFI.new("mg_task_params_t *")
    C.mg_task_method_find(b"000").params(p)
    assert C.mg_paper_task_init(paper, C.mg_task_method_find(b"000"), p, 0) == 0
    _, ctx = _board_planner(py.p)
    C.mg_method000_set_board_planner(FFI.addressof(paper, "task"), ctx)
    return paper, ctx


def test_the_back_off_of_000_from_a_cut_symbol():
    """SEARCH at the start sees the symbol cut at the right border: the base turns right by
    the frame's waist and the half field of view, backs straight off 150 mm at slow_mmps,
    stands until a frame taken after the stop, then looks around again; once a run, and not
    away from the start. Both tasks step for step."""
    py = Task("000")
    paper, _ctx = _paper_c000(py)
    c = FFI.addressof(paper, "task")
    enter_state(py, c, "SEARCH", None, False, (-2500, -200, 2300, 600), (230, 10),
                ("SEARCH", "LOST"))
    out = FFI.new("mg_task_outputs_t *")
    nothing = {"radial_symbol": None}
    cut = {"radial_symbol": None, "radial_cut": CUT(x=210, y=130, w=110, h=60, side=1)}
    now, x, h = 20_000, 0, 0
    res = _step_both(py, c, now, TaskInputs(detections=cut), out, _frame000)
    turn = res.detail["back_off"]["turn_mrad"]
    spin, back = (py.p.turn_wheel_mmps, -py.p.turn_wheel_mmps), (-py.p.slow_mmps,) * 2
    assert res.detail["back_off"]["n"] == 1 and turn < -256  # right, beyond the waist's look
    assert res.wheels_mmps == spin  # on the spot, clockwise
    while res.wheels_mmps == spin:
        now, h = now + 20_000, h - 150
        res = _step_both(py, c, now, TaskInputs(heading_mrad=h, detections=cut), out, _frame000)
    assert -h >= -turn and res.wheels_mmps == back  # turned: straight back
    while res.wheels_mmps == back:
        now, x = now + 20_000, x - 20
        res = _step_both(py, c, now, TaskInputs(x_mm=x, heading_mrad=h, detections=cut), out,
                         _frame000)
    assert x <= -150 and res.wheels_mmps == (0, 0)
    stopped = now
    while now < stopped + py.p.frame_latency_us:  # standing: frames taken before the stop
        now += 20_000
        res = _step_both(py, c, now, TaskInputs(x_mm=x, heading_mrad=h, detections=nothing),
                         out, _frame000)
        assert res.wheels_mmps == (0, 0) and "back_off" not in res.detail
    assert py.ms.back_off is None and c.state == machine.STATES.index("SEARCH")
    for _ in range(20):  # searching again from here: a cut no longer backs off
        now += 100_000
        res = _step_both(py, c, now, TaskInputs(x_mm=x, heading_mrad=h, detections=cut), out,
                         _frame000)
        assert "back_off" not in res.detail and res.wheels_mmps[0] >= 0


def test_no_back_off_away_from_the_start():
    """A cut seen 50 mm from the odometry's origin (the base has moved): no back-off."""
    py = Task("000")
    paper, _ctx = _paper_c000(py)
    c = FFI.addressof(paper, "task")
    out = FFI.new("mg_task_outputs_t *")
    cut = {"radial_symbol": None, "radial_cut": CUT(x=0, y=130, w=110, h=60, side=-1)}
    res = _step_both(py, c, 20_000, TaskInputs(x_mm=30, y_mm=-40, detections=cut), out,
                     _frame000)
    assert "back_off" not in res.detail and py.ms.back_offs == 0


@pytest.mark.parametrize("depth_mm, again_mm, blocked_from_us", [
    (1300, 0, None), (1300, 900, None), (1500, 0, 3_400_000), (700, 0, None)])
def test_the_drive_to_a_far_sighting(depth_mm, again_mm, blocked_from_us):
    """SEARCH's drive to a far sighting not read again at rest (search.py far_step), step by
    step on both tasks with a base that follows the wheels: the turn, the drive (stopped by a
    front sonar from ``blocked_from_us``), the look, the search again; or the sighting seen
    again on the way and approached; a near one dropped as before."""
    py = Task("000")
    paper, c = _paper_task000()
    out = FFI.new("mg_task_outputs_t *")
    x = y = h = 0.0
    wheels, first, phases = (0, 0), None, set()
    for now in range(0, 16_000_000, 20_000):
        dets = {}
        if now == 2_000_000 or (first and again_mm and math.dist((x, y), first) <= again_mm):
            dets = {"radial_symbol": _radial(160 * 16, 120 * 16, depth_mm)}
        sonar = (65535, 65535, 300, 65535, 65535) if blocked_from_us is not None \
            and now >= blocked_from_us else (65535,) * 5
        inp = TaskInputs(x_mm=round(x), y_mm=round(y), heading_mrad=round(h * 1000),
                         sonar_mm=sonar, detections=dets)
        res = _step_both(py, c, now, inp, out, _frame000)
        assert c.far_phase == (["turn", "drive", "look"].index(py.far[0]) + 1 if py.far else 0)
        assert c.far_count == py.far_count
        phases.add(py.far[0] if py.far else None)
        first = first or py.obj
        if res.state != "SEARCH":
            break
        wheels = res.wheels_mmps or wheels
        v, w = (wheels[0] + wheels[1]) / 2, (wheels[1] - wheels[0]) / 300
        h += w * 0.02
        x, y = x + v * math.cos(h) * 0.02, y + v * math.sin(h) * 0.02
    if depth_mm < 1000:
        assert phases == {None} and py.state == "SEARCH"
    elif again_mm:
        assert py.state == "APPROACH"
    else:
        assert phases == {None, "turn", "drive", "look"} and py.state == "SEARCH"


def _search_tasks000(search: dict) -> tuple:
    """000's Python task with ``search`` overrides and the C task as the C program holds it
    with the same parameters: (the C's holders, kept alive, the Python task, the C task)."""
    py = Task("000", {"search": search})
    paper, with_py = FFI.new("mg_paper_task_t *"), _c_task(py)
    assert C.mg_paper_task_init(paper, C.mg_task_method_find(b"000"),
                                FFI.addressof(with_py, "p"), 0) == 0
    return (paper, with_py), py, FFI.addressof(paper, "task")


def _follow(pose: list, wheels: tuple) -> None:
    """The base's pose follows the wheels for 20 ms: a turn in place 40 mrad, a drive its
    speed straight ahead."""
    left, right = wheels
    if left == right:
        pose[0] += round(left * 0.02 * math.cos(pose[2] / 1000))
        pose[1] += round(left * 0.02 * math.sin(pose[2] / 1000))
    else:
        pose[2] += 40 if right > left else -40


def test_legs_past_an_obstacle_step_by_step():
    """000's SEARCH over its rings' legs with echoes beside the way, in it and none (the
    wander's stop, the drive round an obstacle and the leg past it, host/task/search.py
    wander_step): the same wheels, arm targets and detail every step as the Python's."""
    quick = {"theta2_min_mrad": -2200, "d_theta5_mrad": 800, "turns_per_wander": 1,
             "coarse_theta2_mrad": (-2200,), "outward_from_mm": 1000}
    _keep, py, c = _search_tasks000(quick)
    out = FFI.new("mg_task_outputs_t *")
    far = 65535
    beside, ahead, diag = (far, far, far, 300, far), (far, far, 350, far, far), (
        far, 250, far, far, far)
    sonars = [(far,) * 5, ahead, beside, ahead, diag, beside, (600, far, far, far, 450)]
    pose = [0, 0, 0]
    passed = rounds = 0
    for k in range(1100):
        sonar = sonars[k // 400 % len(sonars)]
        passing = py.search is not None and py.search.passing
        res = _step_both(py, c, 20_000 * (k + 1), TaskInputs(
            x_mm=pose[0], y_mm=pose[1], heading_mrad=pose[2], sonar_mm=sonar), out, _frame000)
        _follow(pose, res.wheels_mmps)
        passed += passing and sonar == beside and res.wheels_mmps[0] > 0
        rounds += "wander_round_mrad" in res.detail
    assert passed and rounds and res.state == "SEARCH"


def test_a_leg_stopped_after_a_cut_symbol_looks_step_by_step():
    """000's SEARCH on a leg that sees the symbol cut by the frame's bottom and is then
    stopped by a front sonar (host/task/search.py wander_step, Method000.search_cut_look):
    the turn to face it, the cycle at rest, the next station; a cut at the top of the frame,
    or a tall one, does not look. The same wheels, arm targets and detail every step as the
    Python's."""
    quick = {"theta2_min_mrad": -2200, "d_theta5_mrad": 800, "turns_per_wander": 1,
             "coarse_theta2_mrad": (-2200,)}
    far = 65535
    for cut_y, cut_h, looks in ((200, 40, True), (0, 40, False), (140, 100, False)):
        _keep, py, c = _search_tasks000(quick)
        out = FFI.new("mg_task_outputs_t *")
        pose = [0, 0, 0]
        looked, wandered = 0, 0
        for k in range(900):
            dets = {}
            sonar = (far,) * 5
            if py.search is not None and py.search.wandering and not wandered:
                wandered = k
            if wandered and k == wandered + 10:
                dets = {"radial_symbol": None,
                        "radial_cut": CUT(x=40, y=cut_y, w=130, h=cut_h, side=0)}
            if wandered and wandered + 30 <= k < wandered + 32:
                sonar = (far, far, 300, far, far)
            res = _step_both(py, c, 20_000 * (k + 1), TaskInputs(
                x_mm=pose[0], y_mm=pose[1], heading_mrad=pose[2], sonar_mm=sonar,
                detections=dets), out, _frame000)
            _follow(pose, res.wheels_mmps)
            looked += "wander_look_mrad" in res.detail
        assert wandered and looked == looks and res.state == "SEARCH"
