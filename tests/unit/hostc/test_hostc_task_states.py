"""The C task's states whole (hostc/task_search.c, task_adjust.c, task_grasp.c, sonar_guard.c
and 002's hooks in task_method002.c, on the machine's tables of task_machine.c) against the
Python task (host/task/): the same step inputs give the same servo, wheel and gripper
commands, transitions, state and trace detail, step by step; hypothesis-made sequences from
every state, and the steps the Python host took in the shipped scenarios of 002, replayed on
the C task; the frames' results reach the C task through its detectors' glue."""

from __future__ import annotations

import json

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from test_hostc_app_factory import words
from test_hostc_task import FRAMES, NEAR, RED, recorded_run

from mobigrasp import hostc
from mobigrasp.host.app import jsonable
from mobigrasp.host.search import SearchParams
from mobigrasp.host.task import Task, TaskInputs, machine
from mobigrasp.host.task.sense import CAMERA_002
from mobigrasp.host.vision import registry

FFI, C = hostc.lib()
SETTINGS = examples(60)
ENCODER = json.JSONEncoder(sort_keys=True, separators=(",", ":"))  # the DONE's
HELD = registry.row("held_fill").result_type()
# the C's params named as TaskParams' fields (the rest: tables below)
SCALARS = ("servo_speed_mrad_per_s", "settle_margin_us", "frame_latency_us", "lost_timeout_us",
           "grasp_r_mm", "blind_approach_mm", "blind_keep_mm", "blind_approach_us", "slow_mmps",
           "mount_forward_mm", "h_shoulder_mm", "object_top_mm", "grasp_height_mm", "t_d_px",
           "cylinder_near_px", "cross_near_px", "bearing_tol_mrad", "adjust_theta3_mrad",
           "adjust_theta4_mrad", "blind_finish_mm", "posture_step_mrad", "confirm_us",
           "lost_hold_us", "max_lost", "turn_wheel_mmps", "wander_mmps", "wander_clear_mm",
           "sighting_match_mm", "sonar_offset_mm", "r_r_mm", "sonar_a_g_mrad", "detour_mm",
           "detour_clear_mm", "max_detours", "grasp_r_tol_mm", "hover_mm", "lift_mm",
           "pregrasp_back_mm", "grasp_close_timeout_us")


def _c_params(py):
    """The C task's parameters of a Python task's TaskParams (002's row, then py's fields)."""
    p = FFI.new("mg_task_params_t *")
    C.mg_task_method_find(b"002").params(p)
    for name in SCALARS:
        setattr(p, name, getattr(py, name))
    for i, state in enumerate(machine.STATES):
        p.timeouts_us[i] = py.timeouts_us.get(state, -1)
    sp = SearchParams(**py.search)
    for name, _ in FFI.typeof("mg_search_params_t").fields:
        if name == "coarse_theta2_mrad":
            p.search.coarse_theta2_mrad[0:len(sp.coarse_theta2_mrad)] = list(
                sp.coarse_theta2_mrad)
        elif name != "n_coarse":
            setattr(p.search, name, getattr(sp, name))
    p.search.n_coarse = len(sp.coarse_theta2_mrad)
    for name, value in py.fuzzy.items():
        setattr(p.fuzzy, name, value)
    p.has_object_xy = bool(py.object_xy_mm)
    p.object_xy_mm = list(py.object_xy_mm or (0, 0))
    return p


def _c_task(py: Task):
    t = FFI.new("mg_task_t *")
    assert C.mg_task_init(t, C.mg_task_method_find(b"002"), _c_params(py.p), py.entered_us) == 0
    return t


def test_the_params_of_002_are_the_python_task_s():
    """The method row's parameters, every field the states read, against TaskParams."""
    py = Task("002").p
    c = FFI.new("mg_task_params_t *")
    C.mg_task_method_find(b"002").params(c)
    want = _c_params(py)
    for name in SCALARS:
        assert getattr(c, name) == getattr(want, name), name
    assert list(c.timeouts_us) == list(want.timeouts_us)
    for name, _ in FFI.typeof("mg_search_params_t").fields:
        if name == "coarse_theta2_mrad":
            assert list(c.search.coarse_theta2_mrad)[:c.search.n_coarse] == list(
                SearchParams(**py.search).coarse_theta2_mrad)
        else:
            assert getattr(c.search, name) == getattr(want.search, name), name
    assert c.has_object_xy == 0


def _frame(dets: dict):
    """The detectors' results as the C task reads them: their kernels' out words through the
    C host's glue (hostc/app_factory.c), into 002's frame."""
    f = FFI.new("mg_frame002_t *")
    keep = [FFI.new("int32_t[]", words(n, dets[n])) if dets.get(n) is not None else FFI.NULL
            for n in ("double_cross", "red_cylinder", "red_roi", "held_fill")]
    C.mg_frame002_of(f, *keep, CAMERA_002.f_px)
    return f


def _c_inputs(inp: TaskInputs, frame_of=None):
    """The C's step inputs of a Python TaskInputs (and the frame it points to, kept alive):
    the detections through ``frame_of`` (002's glue by default)."""
    c = FFI.new("mg_task_inputs_t *")
    c.has_joints = inp.joints_mrad is not None
    c.joints_mrad = list(inp.joints_mrad or (0,) * 6)
    c.x_mm, c.y_mm, c.heading_mrad, c.v_mmps = inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps
    c.n_sonar = len(inp.sonar_mm)
    c.sonar_mm[0:len(inp.sonar_mm)] = list(inp.sonar_mm)
    c.grasp_closed = inp.grasp_closed
    frame = (frame_of or _frame)(inp.detections) if inp.detections else None
    c.frame = frame if frame is not None else FFI.NULL
    return c, frame


def _detail(c) -> dict:
    """The C step's detail: key -> its JSON text."""
    assert c.notes_lost == 0
    return {FFI.string(c.notes[i].key).decode(): FFI.string(C.mg_task_note_json(c, i)).decode()
            for i in range(c.n_notes)}


def _events(c) -> list:
    assert c.events_lost == 0
    return [machine.TaskEvent(e.t_us, machine.STATES[getattr(e, "from")], machine.STATES[e.to],
                              FFI.string(e.why).decode()) for e in c.events[0:c.n_events]]


def assert_outputs(c, out, now: int, res) -> tuple:
    """The C's step at ``now`` gave the Python step's outputs ``res``: its transitions,
    commands, state and trace detail. Where it was (for the assertions that follow)."""
    where = (now, res.state, res.detail)
    assert _events(c) == res.events, where
    assert (tuple(out.servo_mrad), tuple(out.wheels_mmps), out.gripper_permille,
            machine.STATES[out.state]) == (res.servo_mrad, res.wheels_mmps,
                                           res.gripper_permille, res.state), where
    assert _detail(c) == {k: ENCODER.encode(jsonable(v)) for k, v in res.detail.items()}, where
    return where


def _step_both(py: Task, c, now: int, inp: TaskInputs, out, frame_of=None):
    """One step on both; every output compared (the C's frame through ``frame_of``, 002's
    glue by default). The Python's outputs."""
    res = py.step(now, inp)
    cin, _frame_kept = _c_inputs(inp, frame_of)
    C.mg_task_step(c, now, cin, out)
    where = assert_outputs(c, out, now, res)
    assert (tuple(c.obj_mm) if c.has_obj else None) == py.obj, where
    assert (c.move_done_us, c.obj_seen_us, c.trust_from_us, c.lost) == (
        py.move_done_us, py.obj_seen_us, py.trust_from_us, py.counters["lost"]), where
    assert c.bad_detections == py.counters["bad_detections"], where
    return res


HELD_FILLS = st.none() | st.builds(lambda r, g, b, p: HELD(rgb=(r, g, b), fill_permille=p),
                                   st.integers(0, 255), st.integers(0, 255),
                                   st.integers(0, 255), st.integers(900, 1000))
DETS = st.builds(lambda f, h: {**(f or {}), **({"held_fill": h} if h is not None else {})},
                 FRAMES, HELD_FILLS)
SONAR = st.sampled_from([(), (65535,) * 5]) | st.tuples(
    *[st.sampled_from([0, 65535, 20, 150, 450, 1000]) | st.integers(1, 3000)] * 5)
STEP = st.tuples(st.sampled_from([20_000, 20_000, 60_000, 500_000, 2_000_000]),
                 st.tuples(st.integers(-40, 40), st.integers(-40, 40), st.integers(-300, 300)),
                 SONAR, st.booleans(), DETS)


def enter_state(py: Task, c, state: str, obj, graspable: bool, joints: tuple,
                default_obj: tuple, without_obj: tuple) -> None:
    """Both tasks into ``state`` with the arm at ``joints`` and the estimate ``obj`` (the
    states but ``without_obj`` are entered with one: ``default_obj`` when none is given)."""
    py.arm[2:6] = c.arm[2:6] = list(joints)
    if obj is None and state not in without_obj:
        obj = default_obj
    if obj is not None:
        py.obj = obj
        c.has_obj, c.obj_mm = 1, list(obj)
    py.graspable_seen = c.graspable_seen = graspable
    if state != "SEARCH":
        py.go(0, state, "test")
        C.mg_task_go(c, 0, machine.STATES.index(state), b"test")


@SETTINGS
@given(st.sampled_from([s for s in machine.STATES if s not in machine.TERMINAL]),
       st.none() | st.tuples(NEAR, NEAR), st.booleans(), st.tuples(*[st.integers(-1500, 1500)] * 4),
       st.lists(STEP, min_size=1, max_size=40))
def test_steps_from_every_state(state, obj, graspable, joints, steps):
    """From a state entered with an estimate (or none), a sequence of steps with odometry that
    wanders, sonar rings, the gripper flag and frames of every detector: the same outputs."""
    py = Task("002")
    c = _c_task(py)
    enter_state(py, c, state, obj, graspable, joints, (300, 40), ("SEARCH", "APPROACH", "LOST"))
    out = FFI.new("mg_task_outputs_t *")
    now, x, y, h = 0, 0, 0, 0
    for dt, (dx, dy, dh), sonar, closed, dets in steps:
        now += dt
        x, y, h = x + dx, y + dy, h + dh
        inp = TaskInputs(x_mm=x, y_mm=y, heading_mrad=h, sonar_mm=sonar, grasp_closed=closed,
                         detections=dets)
        _step_both(py, c, now, inp, out)
    assert c.hist_overflow == 0


def test_the_held_colour_of_002():
    """The grasp check's colour rule (the red mask's) on every grey and a few reds."""
    from mobigrasp.host.vision.held_fill import red_paint
    for rgb in [(v, v, v) for v in range(0, 256, 5)] + [
            (r, g, b) for r in range(0, 256, 15) for g in range(0, 256, 30)
            for b in range(0, 256, 30)]:
        assert C.mg_method002_red_paint(list(rgb)) == red_paint(rgb), rgb


def record_steps(mp, calls: list) -> None:
    """A recorder (test_hostc_task.recorded_runs) of the Python task's steps: ``calls[0]`` a
    fresh task as the run's began (its method, parameters and start), then (now, inputs,
    outputs) of each step."""
    orig = machine.Task.step

    def recorded(task, now_us, inputs):
        if not calls:
            calls.append(Task(task.method, start_us=task.entered_us))
            calls[0].p = task.p
        res = orig(task, now_us, inputs)
        calls.append((now_us, inputs, res))
        return res
    mp.setattr(machine.Task, "step", recorded)


def steps_and_fresh(calls: list) -> tuple[list, object]:
    """What ``record_steps`` recorded: (the steps, the fresh task)."""
    return calls[1:], calls[0]


def _recorded_steps(tmp_path, scenario: str) -> tuple[list, object]:
    """The Python task's steps in a shipped scenario run in process: (now, inputs, outputs)."""
    return steps_and_fresh(recorded_run(tmp_path, scenario, record_steps))


def _replay(steps: list, fresh: Task) -> list:
    """The recorded steps on the C task as the C program holds it (task_paper.h), each output
    compared, and as the program reads them; the states passed through."""
    paper = FFI.new("mg_paper_task_t *")
    assert C.mg_paper_task_init(paper, C.mg_task_method_find(b"002"), _c_params(fresh.p),
                                fresh.entered_us) == 0
    c = FFI.addressof(paper, "task")
    out, prog = FFI.new("mg_task_outputs_t *"), FFI.new("mg_task_output_t *")
    states = []
    for now, inp, res in steps:
        cin, _frame_kept = _c_inputs(inp)
        C.mg_task_step(c, now, cin, out)
        C.mg_paper_outputs(paper, out, prog)
        assert [(e.t_us, FFI.string(getattr(e, "from")).decode(), FFI.string(e.to).decode(),
                 FFI.string(e.why).decode()) for e in prog.transitions[0:prog.n_transitions]] \
            == [(e.t_us, e.from_state, e.to_state, e.why) for e in res.events]
        assert {FFI.string(d.key).decode(): FFI.string(d.json).decode()
                for d in prog.detail[0:prog.n_detail]} == {
            k: ENCODER.encode(jsonable(v)) for k, v in res.detail.items()}
        assert (FFI.string(prog.state).decode(), tuple(prog.servo_mrad),
                tuple(prog.wheels_mmps), prog.gripper_permille) == (
            res.state, res.servo_mrad, res.wheels_mmps, res.gripper_permille)
        assert_outputs(c, out, now, res)
        if not states or states[-1] != res.state:
            states.append(res.state)
    assert c.hist_overflow == 0 and paper.transitions_lost == 0
    return states


def test_replay_of_paper002_marker_whole(shared_recording):
    """Every step the Python task took in paper002-marker, SEARCH to DONE, on the C task."""
    steps, fresh = steps_and_fresh(shared_recording("paper002-marker", "steps"))
    assert len(steps) > 500  # 50 steps a simulated second: SEARCH to DONE in ~18 s
    states = _replay(steps, fresh)
    assert states[0] == "SEARCH" and states[-1] == "DONE"
    assert {"APPROACH", "ADJUST", "ROUGH_GRASP", "PRECISE_GRASP", "LIFT"} <= set(states)


@pytest.mark.slow
def test_replay_of_paper002_cylinder_moving_whole(tmp_path):
    """The same for the moving cylinder (002 Fig. 4)."""
    steps, fresh = _recorded_steps(tmp_path, "paper002-cylinder-moving")
    states = _replay(steps, fresh)
    assert states[-1] == "DONE"


@pytest.mark.parametrize("state", machine.STATES)
def test_the_detectors_each_state_runs(state):
    """Task.detectors_needed and detector_fallbacks of 002, by the program's detector order."""
    py, c = Task("002"), _c_task(Task("002"))
    if state != "SEARCH":
        py.go(0, state, "test")
        C.mg_task_go(c, 0, machine.STATES.index(state), b"test")
    names = [FFI.string(C.mg_detector_names[i]).decode() for i in range(C.MG_N_DETECTORS)]
    bits = C.mg_task_detectors_needed(c)
    assert [n for i, n in enumerate(names) if bits >> i & 1] == py.detectors_needed()
    assert {names[i]: names[C.mg_task_detector_fallback(c, i)] for i in range(len(names))
            if C.mg_task_detector_fallback(c, i) >= 0} == py.detector_fallbacks()


def test_the_frame_glue_keeps_a_frame_without_results():
    """A frame whose detectors all found nothing is a frame (APPROACH steers on), not none."""
    f = _frame({"double_cross": None, "red_roi": None})
    assert f.has_frame == 1 and not (f.has_dc or f.has_rc or f.has_roi)


@SETTINGS
@given(st.sampled_from(["SEARCH", "APPROACH", "ADJUST"]), st.none() | st.tuples(NEAR, NEAR),
       st.lists(st.tuples(st.tuples(st.integers(-300, 300), st.integers(-300, 300)),
                          st.tuples(st.integers(-40, 40), st.integers(-40, 40),
                                    st.integers(-400, 400)),
                          SONAR | st.tuples(*[st.sampled_from([65535, 20, 45, 120, 180,
                                                               950])] * 5)),
                min_size=1, max_size=40))
def test_the_sonar_guard(state, obj, steps):
    """The guard after a step's wheels: the stop below R_r unless the echo is the object's,
    the turn to the widest free sector and the drive out; the kept edges of close echoes'
    arcs; in ADJUST the close guard (an echo within CLOSE_GUARD_MM in front of the object, or
    a kept edge the footprint is about to reach: grasp from there, or search again), as
    sonar_guard.py."""
    from mobigrasp.host.task.sonar_guard import SONAR_GUARD
    py = Task("002")
    c = _c_task(py)
    if obj is None and state == "ADJUST":
        obj = (400, 0)  # ADJUST is entered with an estimate
    if obj is not None:
        py.obj = obj
        c.has_obj, c.obj_mm = 1, list(obj)
    py.state, c.state = state, machine.STATES.index(state)
    x = y = h = 0
    for wheels, (dx, dy, dh), sonar in steps:
        x, y, h = x + dx, y + dy, h + dh
        py.wheels = wheels
        c.wheels = list(wheels)
        py._detail, c.n_notes = {}, 0
        inp = TaskInputs(x_mm=x, y_mm=y, heading_mrad=h, sonar_mm=sonar)
        cin, _ = _c_inputs(inp)
        py._events, c.n_events = [], 0
        SONAR_GUARD.step(py, 0, inp)
        C.mg_sonar_guard_step(c, 0, cin)
        assert _events(c) == py._events
        assert tuple(c.wheels) == py.wheels
        assert _detail(c) == {k: ENCODER.encode(jsonable(v)) for k, v in py._detail.items()}
        assert bool(c.guard_out.active) == (py.guard_out is not None)
        assert _side_echoes(c) == py.side_echoes
        if py.guard_out is not None:
            assert (c.guard_out.heading_mrad, c.guard_out.length_mm, c.guard_out.checked) == (
                py.guard_out["heading_mrad"], py.guard_out["length_mm"],
                int(py.guard_out.get("checked", False)))


def _side_echoes(c) -> list:
    return [tuple(c.side_echoes_mm[i]) for i in range(c.n_side_echoes)]


def test_a_post_gone_from_the_cone_stops_adjust_the_same_on_both_tasks():
    """ADJUST: a post read 45 mm from the front sonar, then gone from the cone; the base stops
    once odometry has brought the footprint within CLOSE_SIDE_MM of its arc's kept edges (the
    grasp goes on from there); the reach drive's guard sees the same edges."""
    from mobigrasp.host.task.sonar_guard import CLOSE_SIDE_MM, SONAR_GUARD, close_echo
    py = Task("002")
    c = _c_task(py)
    py.obj = (420, 0)
    c.has_obj, c.obj_mm = 1, [420, 0]
    py.state, c.state = "ADJUST", machine.STATES.index("ADJUST")
    clear = (2500,) * 5
    for x, sonar in [(0, clear), (0, (2500, 2500, 45, 2500, 2500)), (6, clear), (20, clear),
                     (30, clear)]:
        py.wheels, c.wheels = (60, 60), [60, 60]
        py._detail, c.n_notes = {}, 0
        py._events, c.n_events = [], 0
        inp = TaskInputs(x_mm=x, sonar_mm=sonar)
        cin, _ = _c_inputs(inp)
        SONAR_GUARD.step(py, 0, inp)
        C.mg_sonar_guard_step(c, 0, cin)
        assert tuple(c.wheels) == py.wheels and _events(c) == py._events
        assert _detail(c) == {k: ENCODER.encode(jsonable(v)) for k, v in py._detail.items()}
        assert _side_echoes(c) == py.side_echoes
    assert py.wheels == (0, 0) and py.state == "ROUGH_GRASP"
    assert py._detail["close_guard"]["side"] == 1
    assert 0 <= py._detail["close_guard"]["range_mm"] < CLOSE_SIDE_MM
    phi, rng = FFI.new("int32_t *"), FFI.new("int32_t *")
    assert C.mg_close_echo(c, cin, phi, rng) == 2
    echo = close_echo(py, inp)
    assert (phi[0], rng[0]) == (echo["phi_mrad"], echo["range_mm"])


RED_FILL = st.builds(lambda r, g, p: HELD(rgb=(r, g, g // 2), fill_permille=p),
                     st.integers(150, 255), st.integers(0, 60), st.integers(900, 1000))


@SETTINGS
@given(st.sampled_from([(0, 0)] * 3) | st.tuples(st.integers(-40, 40), st.integers(-8, 8)),
       st.lists(st.tuples(st.sampled_from([60_000] * 4 + [20_000, 200_000]),
                          st.none() | st.fixed_dictionaries({"held_fill": RED_FILL | HELD_FILLS},
                                                            optional={"red_cylinder": FRAMES.map(
                                                                lambda f: (f or {}).get(
                                                                    "red_cylinder"))})),
                min_size=100, max_size=100))
def test_the_grasp_and_its_check(obj, steps):
    """ROUGH_GRASP to LIFT with the gripper closed: the drive into the level grasp's reach,
    the rough pose, the move in and close, the lift, the grasp check's looks at the waist
    offsets with the held cylinder's red filling the frame (DONE) or the cylinder seen
    standing away (a miss: ADJUST), as grasp.py."""
    _grasp_both(obj, steps)


def _grasp_both(obj: tuple, steps: list, sonar: tuple = ()) -> str:
    """The grasp states on both tasks from ROUGH_GRASP, the base still, the object ``obj``
    off the level grasp's reach, the sonar ring reading ``sonar``; the Python task's last
    state."""
    py = Task("002")
    c = _c_task(py)
    centre, _ = py.rules.grasp_reach_mm(py)
    # the base stands still: the object at the level grasp's reach, or off it by obj
    obj = (py.p.mount_forward_mm + centre + obj[0], obj[1])
    py.obj = obj
    c.has_obj, c.obj_mm = 1, list(obj)
    py.graspable_seen = c.graspable_seen = True
    py.go(0, "ROUGH_GRASP", "test")
    C.mg_task_go(c, 0, C.MG_ROUGH_GRASP, b"test")
    out = FFI.new("mg_task_outputs_t *")
    now = 0
    for dt, dets in steps:
        now += dt
        inp = TaskInputs(grasp_closed=True, detections=dets or {}, sonar_mm=sonar)
        _step_both(py, c, now, inp, out)
        NOTED.update(py._detail)
    return py.state


NOTED: dict = {}  # the detail members the grasp runs noted


def test_the_reach_drive_stops_at_an_echo_in_front():
    """The drive into the grasp's reach (the object 30 mm beyond it) meets an echo 20 mm ahead
    of the ring that is not the object's: it tries the grasp from there (here out of the
    rough pose's reach: FAILED), the same on both tasks."""
    NOTED.clear()
    fill = HELD(rgb=(200, 20, 10), fill_permille=950)
    assert _grasp_both((30, 0), [(60_000, {"held_fill": fill})] * 40,
                       (2500, 2500, 20, 2500, 2500)) == "FAILED"
    assert NOTED["close_guard"] == {"phi_mrad": 0, "range_mm": 20, "close_mm": 30}


@pytest.mark.parametrize("seen_standing, end", [(False, "DONE"), (True, "ADJUST")])
def test_a_grasp_held_and_one_missed(seen_standing, end):
    """The grasp from the rough pose to the check's verdict: the red filling the frame at two
    waist offsets (DONE), or the cylinder seen standing away from the gripper (a miss)."""
    fill = HELD(rgb=(200, 20, 10), fill_permille=950)
    standing = RED(u_c_q4=160 * 16, v_c_q4=120 * 16, ring1_v_q4=0, ring2_v_q4=640,
                   d_pixel_q4=640, width_q4=400, roi=(0, 0, 1, 1))
    dets = {"held_fill": fill, **({"red_cylinder": standing} if seen_standing else {})}
    assert _grasp_both((0, 0), [(60_000, dets)] * 100) == end


@pytest.mark.parametrize("seen_since, close_by", [(False, None), (True, None),
                                                  (False, "precise"), (False, "ik")])
def test_a_grasp_again_after_no_evidence(seen_since, close_by):
    """A blind grasp (002's move-in) whose check sees nothing (no evidence): open and ADJUST,
    the sighting before dropped on both tasks; the next ROUGH_GRASP with no sighting since
    searches (LOST), with one grasps again. A close decided on the camera's view (as if the
    spoke or 001's look had decided it) keeps the sighting. The same steps on both tasks."""
    py = Task("002")
    c = _c_task(py)
    centre, _ = py.rules.grasp_reach_mm(py)
    py.obj = (py.p.mount_forward_mm + centre, 0)
    c.has_obj, c.obj_mm = 1, list(py.obj)
    py.graspable_seen = c.graspable_seen = py.object_sighted = c.object_sighted = True
    py.go(0, "ROUGH_GRASP", "test")
    C.mg_task_go(c, 0, C.MG_ROUGH_GRASP, b"test")
    out = FFI.new("mg_task_outputs_t *")
    now = 0
    while py.state != "ADJUST":
        now += 60_000
        _step_both(py, c, now, TaskInputs(grasp_closed=True), out)
        if py.state == "LIFT" and close_by:
            py.close_by = close_by
            c.has_close_by, c.close_by = 1, close_by.encode()
        assert now < 60_000_000, py.state
    kept = close_by is not None
    assert (py.regrasps, c.regrasps, py.object_sighted, c.object_sighted) == (1, 1, kept, kept)
    py.object_sighted = c.object_sighted = seen_since or kept
    py.go(now, "ROUGH_GRASP", "test")
    C.mg_task_go(c, now, C.MG_ROUGH_GRASP, b"test")
    res = _step_both(py, c, now + 60_000, TaskInputs(), out)
    lost = [e for e in res.events if e.to_state == "LOST"]
    assert bool(lost) != (seen_since or kept), res.events
    assert all(e.why.startswith("grasp missed at the estimate, object not seen since")
               for e in lost)


@pytest.mark.parametrize("red_seen, end, why", [
    (True, "LOST", "object never sighted at its estimated place, its cue seen before"),
    (False, "FAILED", "no graspable object found (red_cylinder never seen)")])
def test_the_grasp_on_an_estimate_the_rings_never_confirmed(red_seen, end, why):
    """ROUGH_GRASP entered with the rings never measured (ADJUST finished on the estimate of
    the ROI or the crosses): the red cylinder's ROI seen in the approach, the search goes on
    (LOST); the board alone, FAILED "no graspable object found"; the same on both tasks."""
    py = Task("002")
    c = _c_task(py)
    py.obj = (300, 0)
    c.has_obj, c.obj_mm = 1, [300, 0]
    py.graspable_seen = c.graspable_seen = False
    py.ms.red_seen = red_seen
    FFI.cast("mg_state002_t *", c.ms.bytes).red_seen = red_seen
    py.go(0, "ROUGH_GRASP", "test")
    C.mg_task_go(c, 0, C.MG_ROUGH_GRASP, b"test")
    out = FFI.new("mg_task_outputs_t *")
    events = []
    for k in range(1, 4):
        events += _step_both(py, c, k * 20_000, TaskInputs(detections={}), out).events
    event = next(e for e in events if e.from_state == "ROUGH_GRASP")
    assert (event.to_state, event.why.startswith(why)) == (end, True), event
    if red_seen:  # the estimate looked at and not seen there is dropped on both
        assert (py.obj, c.has_obj) == (None, 0)
