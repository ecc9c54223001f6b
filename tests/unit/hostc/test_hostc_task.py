"""The C task (hostc/task_machine.c, task_method.c, task_method002.c, task_drive.c) against the
Python one (host/task/): the same calls with the same inputs give the same arm targets, settle
times, histories, transitions and wheel commands, step by step; hypothesis-made sequences, and
the sequence the Python host made in the shipped scenario paper002-marker, replayed."""

from __future__ import annotations

import contextlib

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from test_hostc_arm_kinematics import _assert_same_ik

from mobigrasp import hostc
from mobigrasp.host.control.fuzzy import FuzzyApproach, FuzzyParams
from mobigrasp.host.kinematics import PAPER_000, PAPER_002
from mobigrasp.host.task import Task, TaskInputs, drive, machine, sense
from mobigrasp.host.task.adjust import ADJUST, AdjustState
from mobigrasp.host.task.method import METHODS
from mobigrasp.host.task.method002 import BOARD_ALONE_FRAMES, Method002
from mobigrasp.host.task.params import TaskParams
from mobigrasp.host.task.sense import CAMERA_002
from mobigrasp.host.vision import registry
from mobigrasp.host.vision.double_cross import level_pair

FFI, C = hostc.lib()
SETTINGS = examples(100)
ANGLE = st.integers(-4000, 4000)
WHY_BYTES = len(FFI.new("mg_task_event_t *").why)  # a transition's reason, its 0 included
# gaps between calls that meet the limits exactly (1 s of history, the timeouts), and others
TICKS = st.sampled_from([20_000, 100_000, 250_000, 500_000, 1_000_000]) | st.integers(1, 400_000)


def _c_task(start_us: int = 0, timeouts_us: dict | None = None):
    rules = C.mg_task_method_find(b"002")
    p = FFI.new("mg_task_params_t *")
    rules.params(p)
    for state, limit in (timeouts_us or {}).items():
        p.timeouts_us[machine.STATES.index(state)] = limit
    t = FFI.new("mg_task_t *")
    assert C.mg_task_init(t, rules, p, start_us) == 0
    return t


def _ms(t):
    return FFI.cast("mg_state002_t *", t.ms.bytes)


def _events(t) -> list:
    assert t.events_lost == 0
    return [machine.TaskEvent(e.t_us, machine.STATES[getattr(e, "from")], machine.STATES[e.to],
                              FFI.string(e.why).decode())
            for e in t.events[0:t.n_events]]


def _load(t, arm, move_done_us: int) -> None:
    t.arm[0:6] = list(arm)
    t.move_done_us = move_done_us


def test_the_method_table_and_the_states():
    names = {FFI.string(C.mg_task_methods[i].name).decode() for i in range(C.mg_n_task_methods)}
    assert names and names <= set(METHODS)
    assert C.mg_task_method_find(b"003") == FFI.NULL
    assert [FFI.string(C.mg_task_state_name(i)).decode() for i in range(C.MG_N_TASK_STATES)] \
        == list(machine.STATES)
    assert [C.mg_task_terminal(i) for i in range(C.MG_N_TASK_STATES)] \
        == [s in machine.TERMINAL for s in machine.STATES]


def test_params_are_those_of_the_python_task():
    py, ct = TaskParams.for_method("002"), _c_task()
    c = ct.p
    assert [c.timeouts_us[i] for i in range(C.MG_N_TASK_STATES)] \
        == [py.timeouts_us.get(s, -1) for s in machine.STATES]
    for name in ("servo_speed_mrad_per_s", "settle_margin_us", "frame_latency_us",
                 "lost_timeout_us", "grasp_r_mm", "blind_approach_mm", "blind_keep_mm",
                 "blind_approach_us", "slow_mmps", "t_d_px", "posture_step_mrad",
                 "mount_forward_mm", "h_shoulder_mm", "object_top_mm", "grasp_height_mm",
                 "cylinder_near_px", "cross_near_px", "bearing_tol_mrad",
                 "adjust_theta3_mrad", "adjust_theta4_mrad", "blind_finish_mm"):
        assert getattr(c, name) == getattr(py, name), name
    task = Task("002")
    pp = task.posture_params(7)
    cp = C.mg_task_posture_params(ct, 7)
    assert (tuple(cp.k_theta_q12), cp.margin_mode, cp.max_step_mrad) \
        == (pp.k_theta_q12, ["printed", "limits"].index(pp.margin_mode), 7)
    cam, g = ct.cam, ct.geom
    assert (g.l1_mm_q4, g.l2_mm_q4, g.l3_mm_q4) == (task.geom.l1_mm_q4, task.geom.l2_mm_q4,
                                                   task.geom.l3_mm_q4)
    assert (cam.f_px, cam.u0_px, cam.v0_px) == (task.cam.f_px, task.cam.u0_px, task.cam.v0_px)
    fz = FuzzyParams(**py.fuzzy)
    assert (c.fuzzy.e_th_mrad, c.fuzzy.e_cth_mrad_s, c.fuzzy.u_th_mrad, c.fuzzy.v_avg_mm_s,
            c.fuzzy.k_uc_q12, c.fuzzy.t_d_px) == (fz.e_th_mrad, fz.e_cth_mrad_s, fz.u_th_mrad,
                                                 fz.v_avg_mm_s, fz.k_uc_q12, fz.t_d_px)


@SETTINGS
@given(st.integers(-10**12, 10**12))
def test_wrap(a):
    assert C.mg_task_wrap_mrad(a) == drive.wrap_mrad(a)


OPS = st.one_of(
    st.tuples(st.just("arm"), ANGLE, ANGLE, ANGLE, ANGLE, st.none() | ANGLE),
    st.tuples(st.just("remember"), st.integers(-10**6, 10**6), st.integers(-10**6, 10**6),
              st.integers(-3142, 3141)),
    st.tuples(st.just("query"), st.integers(-200_000, 1_500_000)),
    st.tuples(st.just("go"), st.sampled_from(machine.STATES), st.text(max_size=40)),
    st.tuples(st.just("fail"), st.booleans(),
              st.sampled_from(["timeout", "no graspable object found: x", "IK: out of reach"])))


@SETTINGS
@given(st.integers(0, 10**9), st.lists(st.tuples(TICKS, OPS),
                                       max_size=60))
def test_the_shared_bookkeeping(start_us, ops):
    """set_arm, settled, remember, arm_at, pose_at, go and fail on both, op by op."""
    py, c = Task("002", start_us=start_us), _c_task(start_us)
    now = start_us
    for dt, op in ops:
        now += dt
        py._events, c.n_events = [], 0
        if op[0] == "arm":
            th1 = op[5]
            py.set_arm(now, *op[1:5], th1=th1)
            C.mg_task_set_arm(c, now, *op[1:5], th1 is not None, th1 or 0)
        elif op[0] == "remember":
            inp = TaskInputs(x_mm=op[1], y_mm=op[2], heading_mrad=op[3])
            py.remember(now, inp)
            C.mg_task_remember(c, now, *op[1:4])
        elif op[0] == "query":
            arm = FFI.new("int32_t[6]")
            C.mg_task_arm_at(c, now - op[1], arm)
            assert tuple(arm) == py.arm_at(now - op[1])
            at, pose = FFI.new("int64_t *"), FFI.new("int32_t[3]")
            has = C.mg_task_pose_at(c, now - op[1], at, pose)
            assert has == bool(py.pose_hist)
            if has:
                assert (at[0], *pose) == py.pose_at(now - op[1])
        elif op[0] == "go":
            py.go(now, op[1], op[2])
            C.mg_task_go(c, now, machine.STATES.index(op[1]), op[2].encode())
        else:
            py.graspable_seen = c.graspable_seen = op[1]
            py.fail(now, op[2])
            C.mg_task_fail(c, now, op[2].encode())
            assert FFI.string(c.failure).decode() == py.failure
        assert list(c.arm) == py.arm and c.move_done_us == py.move_done_us
        assert C.mg_task_settled(c, now) == py.settled(now)
        assert (machine.STATES[c.state], c.entered_us, c.entry_pending) \
            == (py.state, py.entered_us, py.entry_pending)
        assert _events(c) == py._events
        assert c.n_arm_hist == len(py.arm_hist) and c.n_pose_hist == len(py.pose_hist)
    assert c.hist_overflow == 0


@SETTINGS
@given(st.dictionaries(st.sampled_from([s for s in machine.STATES if s not in machine.TERMINAL]),
                       st.sampled_from([100_000, 200_000, 1_000_000, 2_000_000]), max_size=7),
       st.lists(st.tuples(st.sampled_from([20_000, 100_000, 500_000]),
                          st.none() | st.tuples(*[ANGLE] * 6),
                          st.integers(-10**5, 10**5), st.integers(-10**5, 10**5),
                          st.integers(-3142, 3141), st.sampled_from(machine.STATES)),
                max_size=40))
def test_the_step_timeouts_and_outputs(timeouts, steps):
    """The machine's step around its states (their actions left out on both sides): timeouts,
    the history, the wheels stopped in a terminal state, the clamped servo targets."""
    py, c = Task("002", params={"timeouts_us": timeouts}), _c_task(0, timeouts)
    for i in range(C.MG_N_TASK_STATES):  # the states' actions left out here too
        c.entry[i] = c.step[i] = FFI.NULL
    rules = FFI.new("mg_task_method_t *", c.rules[0])  # the row without the wheels' guard
    rules.guard_wheels = FFI.NULL
    c.rules = rules
    out = FFI.new("mg_task_outputs_t *")
    inp_c = FFI.new("mg_task_inputs_t *")
    now = 0
    with pytest.MonkeyPatch.context() as mp:
        for table in ("ENTRY", "STEP"):
            mp.setattr(machine, table, {s: (lambda *a: None) for s in machine.STATES})
        mp.setattr(Method002, "guard_wheels", lambda *a: None)
        for dt, joints, x, y, h, jump in steps:
            now += dt
            py.wheels = (c.wheels[0], c.wheels[1]) = (x % 300, -(y % 300))
            res = py.step(now, TaskInputs(joints_mrad=joints, x_mm=x, y_mm=y, heading_mrad=h))
            inp_c.has_joints = joints is not None
            inp_c.joints_mrad[0:6] = list(joints or (0,) * 6)
            inp_c.x_mm, inp_c.y_mm, inp_c.heading_mrad = x, y, h
            C.mg_task_step(c, now, inp_c, out)
            assert _events(c) == res.events
            assert (tuple(out.servo_mrad), tuple(out.wheels_mmps), out.gripper_permille,
                    machine.STATES[out.state]) == (res.servo_mrad, res.wheels_mmps,
                                                   res.gripper_permille, res.state)
            assert tuple(c.joints) == py.joints
            if jump not in machine.TERMINAL and res.state not in machine.TERMINAL:
                py.go(now, jump, "test")
                C.mg_task_go(c, now, machine.STATES.index(jump), b"test")


def _blind(t) -> tuple | None:
    ms = _ms(t)
    return tuple(ms.blind) if ms.has_blind else None


def _back_off(t) -> tuple:
    """002's cut and back-off state as the Python's (cut, back_offs, back_off)."""
    ms = _ms(t)
    under_way = (ms.back_off_from[0], ms.back_off_from[1],
                 ms.back_off_ended_us if ms.back_off_has_ended else None)
    return bool(ms.cut), ms.back_offs, under_way if ms.has_back_off else None


BLIND_OPS = st.one_of(
    st.tuples(st.just("bearing"), st.integers(-3142, 3141),
              st.none() | st.sampled_from([700, 1700]) | st.integers(-500, 4000),
              st.integers(-3000, 3000), st.integers(-3000, 3000), st.integers(-3142, 3141)),
    st.tuples(st.just("blind"), st.integers(-3000, 3000), st.integers(-3000, 3000),
              st.integers(-9000, 9000)),
    st.tuples(st.just("seen"),))


@SETTINGS
@given(st.lists(st.tuples(st.integers(1, 3_000_000), BLIND_OPS), max_size=40))
def test_the_blind_approach_of_002(ops):
    """remember_bearing and approach_blind: the wheels of the fuzzy step (eqs. (1), (2) of
    002), the waist toward the bearing, the settle time, the bearing kept."""
    py, c = Task("002"), _c_task()
    rules, now = Method002(), 0
    rules.enter_approach(py, 0, TaskInputs())
    C.mg_method002_enter_approach(c, FFI.new("mg_task_inputs_t *"))
    assert _ms(c).has_fuzzy and _blind(c) is None
    u = FFI.new("int32_t *")
    for dt, op in ops:
        now += dt
        if op[0] == "seen":
            py.obj_seen_us = c.obj_seen_us = now
            continue
        inp = TaskInputs(x_mm=op[-3], y_mm=op[-2], heading_mrad=op[-1])
        inp_c = FFI.new("mg_task_inputs_t *", {"x_mm": inp.x_mm, "y_mm": inp.y_mm,
                                               "heading_mrad": inp.heading_mrad})
        if op[0] == "bearing":
            rules.remember_bearing(py, inp, op[1], op[2])
            C.mg_method002_remember_bearing(c, inp_c, op[1], op[2] is not None, op[2] or 0)
        else:
            py._detail = {}
            driving = rules.approach_blind(py, now, inp)
            assert C.mg_method002_approach_blind(c, now, inp_c, u) == driving
            if driving:
                assert u[0] == py._detail["fuzzy"]["u_mrad"]
        assert _blind(c) == py.ms.blind
        assert (tuple(c.wheels), list(c.arm), c.move_done_us) == (py.wheels, py.arm,
                                                                  py.move_done_us)


@SETTINGS
@given(st.integers(100, 400), st.integers(0, 10**7), st.integers(0, 10**7))
def test_the_adjust_goal_of_002(grasp_r_mm, seen_us, trust_us):
    py, c = Task("002", params={"grasp_r_mm": grasp_r_mm}), _c_task()
    c.p.grasp_r_mm = grasp_r_mm
    py.obj_seen_us = c.obj_seen_us = seen_us
    py.trust_from_us = c.trust_from_us = trust_us
    goal, tol = FFI.new("int32_t *"), FFI.new("int32_t *")
    C.mg_method002_adjust_goal_mm(c, goal, tol)
    assert (goal[0], tol[0]) == Method002().adjust_goal_mm(py)
    assert C.mg_method002_adjust_vmax_mmps(FFI.addressof(c, "p")) \
        == Method002().adjust_vmax_mmps(py.p)


RED = registry.row("red_cylinder").result_type()


def _red(d_pixel_q4: int):
    return RED(u_c_q4=160 * 16, v_c_q4=120 * 16, ring1_v_q4=0, ring2_v_q4=d_pixel_q4,
               d_pixel_q4=d_pixel_q4, width_q4=16, roi=(0, 0, 1, 1))


@SETTINGS
@given(st.lists(st.tuples(TICKS, st.tuples(*[ANGLE] * 4), st.none() | st.integers(-500, 4500),
                          st.integers(-3142, 3141)), max_size=30))
def test_the_marker_tracking_of_002(steps):
    """The waist toward e a step at a time, the pitch of the marker's row by eq. (10) of 000."""
    py, c = Task("002"), _c_task()
    now = 0
    for dt, joints, vm_q4, e in steps:
        now += dt
        py.set_arm(now, *joints)
        C.mg_task_set_arm(c, now, *joints, 0, 0)
        Method002().track_marker(py, now, vm_q4, e)
        C.mg_method002_track_marker(c, now, vm_q4 is not None, vm_q4 or 0, e)
        assert (list(c.arm), c.move_done_us) == (py.arm, py.move_done_us)


@SETTINGS
@given(st.none() | st.integers(0, 2000) | st.sampled_from([720, 721, 724, 728, 732, 1000]),
       st.integers(0, 10**6), st.integers(0, 10**6), st.integers(0, 2000))
def test_the_stop_rule_of_002(d_pixel_q4, now, trust_us, dist_mm):
    """d_pixel > T_d (002 section 4) stops the base and starts the grasp, as the Python says."""
    py, c = Task("002"), _c_task()
    py.trust_from_us = c.trust_from_us = trust_us
    py.wheels = (c.wheels[0], c.wheels[1]) = (50, 60)
    py._events = []
    done = Method002().adjust_done(py, now, None if d_pixel_q4 is None else _red(d_pixel_q4),
                                   dist_mm)
    assert C.mg_method002_adjust_done(c, now, d_pixel_q4 is not None, d_pixel_q4 or 0,
                                      dist_mm) == done
    assert _events(c) == py._events and tuple(c.wheels) == py.wheels


NEAR = st.integers(-3000, 3000)
ROI = registry.row("red_roi")


def _sighting(name: str, det) -> dict:
    """What the detectors' glue gives the C of a SEARCH sighting."""
    if name == "double_cross":
        return {"steer_on": C.MG_STEER_DOUBLE_CROSS, "u_q4": det.um_q4,
                "d_pixel_q4": det.d_pixel_q4}
    seen = ROI.sighting_fn()(det, CAMERA_002.f_px)
    return {"steer_on": C.MG_STEER_RED_CYLINDER, "u_q4": det.u_c_q4,
            "has_range": seen is not None, "range_mm": 0 if seen is None else seen[2] // 16}


@SETTINGS
@given(st.lists(st.tuples(TICKS, ANGLE, st.booleans(), st.integers(-2000, 7000),
                          st.integers(0, 4000), st.integers(1, 200), st.integers(1, 200),
                          st.booleans()), max_size=20))
def test_the_search_sighting_of_002(steps):
    """SEARCH's sighting: the bearing e of the double cross or of the red ROI's column, its
    spacing or range kept for the approach, and the transition's reason."""
    py, c = Task("002"), _c_task()
    rules, now = Method002(), 0
    why = FFI.new("char[]", WHY_BYTES)
    for dt, th5, cross, u_q4, d_q4, w, h, edge in steps:
        now += dt
        py.set_arm(now, *py.arm[2:5], th5)
        C.mg_task_set_arm(c, now, *c.arm[2:5], th5, 0, 0)
        py.remember(now, TaskInputs())
        C.mg_task_remember(c, now, 0, 0, 0)
        if cross:
            name, det = "double_cross", registry.row("double_cross").result_type()(
                u1_q4=0, v1_q4=0, u2_q4=0, v2_q4=0, um_q4=u_q4, vm_q4=0, d_pixel_q4=d_q4,
                e_mrad=0, votes=(1, 1))
        else:
            name, det = "red_roi", ROI.result_type()(u_c_q4=u_q4, v_c_q4=0, roi=(0, 0, w, h),
                                                      area_px=w * h, touches_edge=edge)
        assert rules.found(py, now, TaskInputs(), name, det)
        assert C.mg_method002_found(c, now, FFI.new("mg_sighting002_t *", _sighting(name, det)))
        ms = _ms(c)
        assert (ms.e_mrad, c.obj_seen_us) == (py.ms.e_mrad, py.obj_seen_us)
        assert (ms.e_dpx if ms.has_e_dpx else None) == py.ms.e_dpx
        assert (ms.e_range_mm if ms.has_e_range else None) == py.ms.e_range_mm
        C.mg_method002_found_why(c, why, WHY_BYTES)
        assert FFI.string(why).decode() == rules.found_why(py)


@SETTINGS
@given(st.lists(st.tuples(st.tuples(*[ANGLE] * 4), st.none() | st.tuples(NEAR, NEAR), NEAR, NEAR,
                          st.integers(-3142, 3141), st.booleans()), max_size=20))
def test_the_look_at_the_object(steps):
    """The posture adjustment (eq. (10) of 000) toward the odometry estimate, at 002's looks."""
    py, c = Task("002"), _c_task()
    for joints, obj, x, y, h, top in steps:
        py.arm[2:6] = c.arm[2:6] = list(joints)
        py.obj = obj
        c.has_obj = obj is not None
        c.obj_mm = obj or (0, 0)
        inp = TaskInputs(x_mm=x, y_mm=y, heading_mrad=h)
        py.look_at_object(inp, top)
        C.mg_task_look_at_object(c, FFI.new("mg_task_inputs_t *", _xyh((x, y, h))), top)
        assert list(c.arm) == py.arm


@examples(30)
@given(st.integers(0, 300), st.integers(0, 300))
def test_the_level_grasp_reach_of_002(grasp_height_mm, h_shoulder_mm):
    """The level grasp's window (eq. (4) of 002) scanned as the Python scans it."""
    py = Task("002", params={"grasp_height_mm": grasp_height_mm, "h_shoulder_mm": h_shoulder_mm})
    c = _c_task()
    c.p.grasp_height_mm, c.p.h_shoulder_mm = grasp_height_mm, h_shoulder_mm
    centre, half = FFI.new("int32_t *"), FFI.new("int32_t *")
    has = C.mg_method002_grasp_reach_mm(c, centre, half)
    assert ((centre[0], half[0]) if has else None) == Method002().grasp_reach_mm(py)


@SETTINGS
@given(st.tuples(st.integers(-400 * 16, 400 * 16), st.integers(-400 * 16, 400 * 16),
                 st.integers(-300 * 16, 300 * 16)))
def test_the_grasp_ik_of_002(target):
    """Level first (eq. (4) of 002), then tilted down: the first reachable pitch's pose, or
    the level pitch's reason."""
    pose, detail = FFI.new("mg_arm_pose_t *"), FFI.new("int64_t *")
    code = C.mg_method002_grasp_ik(FFI.addressof(_c_task(), "geom"), target, pose, detail)
    _assert_same_ik(code, pose, detail[0], Method002().grasp_ik(PAPER_002, target))


@SETTINGS
@given(st.tuples(*[ANGLE] * 4), st.integers(0, 200))
def test_the_held_view_of_002(joints, h_shoulder_mm):
    """The grasp check's look: the first reachable of the held views along the tip's bearing."""
    py, c = Task("002", params={"h_shoulder_mm": h_shoulder_mm}), _c_task()
    c.p.h_shoulder_mm = h_shoulder_mm
    py.arm[2:6] = c.arm[2:6] = list(joints)
    pose = FFI.new("mg_arm_pose_t *")
    has = C.mg_method002_held_view_pose(c, pose)
    expect = Method002().held_view_pose(py)
    assert ((pose.theta2_mrad, pose.theta3_mrad, pose.theta4_mrad, pose.theta5_mrad)
            if has else None) == (None if expect is None else (
                expect.theta2_mrad, expect.theta3_mrad, expect.theta4_mrad, expect.theta5_mrad))


@SETTINGS
@given(st.lists(st.tuples(TICKS, st.tuples(*[ANGLE] * 4), st.sampled_from([0, 0, 700]),
                          st.tuples(NEAR, NEAR, st.integers(-3142, 3141)),
                          st.tuples(st.integers(0, 320 * 16), st.integers(0, 240 * 16),
                                    st.integers(-16, 120 * 16), st.integers(1, 200 * 16)),
                          st.integers(0, 300_000)), max_size=25))
def test_seeing_the_red_cylinder(steps):
    """The object estimate from a red cylinder's rings (002 section 4) seen with the arm and
    base of its capture, into the odometry frame; unusable sightings counted."""
    py, c = Task("002"), _c_task()
    position = FFI.addressof(C, "mg_method002_red_cylinder_position")
    now = 0
    for dt, joints, roll, (x, y, h), (u, v, d, w), trust_back in steps:
        now += dt
        py.set_arm(now, *joints, th1=roll)
        C.mg_task_set_arm(c, now, *joints, 1, roll)
        py.trust_from_us = c.trust_from_us = now - trust_back
        inp = TaskInputs(x_mm=x, y_mm=y, heading_mrad=h)
        inp_c = FFI.new("mg_task_inputs_t *", _xyh((x, y, h)))
        seen = py.see_object(now, inp, "red_cylinder", RED(
            u_c_q4=u, v_c_q4=v, ring1_v_q4=0, ring2_v_q4=d, d_pixel_q4=d, width_q4=w,
            roi=(0, 0, 1, 1)))
        det = FFI.new("mg_red_cylinder_seen_t *", (u, v, d, w))
        assert C.mg_task_see_object(c, now, inp_c, position, det, 1) == seen
        assert (c.bad_detections, c.graspable_seen, c.object_sighted) == (
            py.counters["bad_detections"], py.graspable_seen, py.object_sighted)
        assert (tuple(c.obj_mm) if c.has_obj else None) == py.obj
        assert c.obj_seen_us == py.obj_seen_us
        py.remember(now, inp)
        C.mg_task_remember(c, now, x, y, h)


CROSS = registry.row("double_cross")
PX_U, PX_V = st.integers(0, 320 * 16), st.integers(0, 240 * 16)
FRAMES = st.none() | st.fixed_dictionaries({}, optional={
    "double_cross": st.none() | st.builds(
        lambda u, v, d, tilt: CROSS.result_type()(
            u1_q4=0, v1_q4=0, u2_q4=0, v2_q4=d if tilt else 0, um_q4=u, vm_q4=v, d_pixel_q4=d,
            e_mrad=0, votes=(1, 1)),  # tilt: a pair far from level
        PX_U, PX_V, st.integers(0, 150 * 16), st.booleans()),
    "red_cylinder": st.none() | st.builds(
        lambda u, v, d, w: RED(u_c_q4=u, v_c_q4=v, ring1_v_q4=0, ring2_v_q4=d, d_pixel_q4=d,
                               width_q4=w, roi=(0, 0, 1, 1)),
        PX_U, PX_V, st.integers(-16, 40 * 16), st.integers(1, 100 * 16)),
    "red_roi": st.none() | st.builds(
        lambda u, v, x, y, w, h, edge: ROI.result_type()(u_c_q4=u, v_c_q4=v, roi=(x, y, w, h),
                                                         area_px=w * h, touches_edge=edge),
        PX_U, PX_V, st.sampled_from([0, 2, 150, 300]), st.sampled_from([0, 2, 100]),
        st.integers(1, 100), st.integers(1, 200), st.booleans())})


def _frame002(dets: dict | None):
    """The C's view of one frame's results (the detectors' glue)."""
    f = FFI.new("mg_frame002_t *")
    if not dets:
        return f
    f.has_frame = 1
    dc, rc, roi = (dets.get(k) for k in ("double_cross", "red_cylinder", "red_roi"))
    if dc is not None:
        f.has_dc, f.dc_um_q4, f.dc_vm_q4, f.dc_d_pixel_q4 = 1, dc.um_q4, dc.vm_q4, dc.d_pixel_q4
        seen = CROSS.sighting_fn()(dc, CAMERA_002.f_px)
        f.has_dc_sighting = seen is not None
        f.dc_sighting = seen or (0, 0, 0)
        f.dc_level = int(level_pair(dc))
    if rc is not None:
        f.has_rc, f.rc = 1, (rc.u_c_q4, rc.v_c_q4, rc.d_pixel_q4, rc.width_q4)
    if roi is not None:
        f.has_roi, f.roi_u_c_q4, f.roi_v_c_q4 = 1, roi.u_c_q4, roi.v_c_q4
        f.roi_box = list(roi.roi)
        seen = ROI.sighting_fn()(roi, CAMERA_002.f_px)
        f.has_roi_sighting = seen is not None
        f.roi_sighting = seen or (0, 0, 0)
    return f


@SETTINGS
@given(st.integers(-3142, 3141), st.none() | st.integers(1, 200),
       st.lists(st.tuples(st.sampled_from([20_000, 40_000, 500_000, 1_500_000]), FRAMES,
                          st.tuples(NEAR, NEAR, st.integers(-3142, 3141))), max_size=30))
def test_the_fuzzy_approach_of_002(e0, dpx0, steps):
    """APPROACH of 002 step by step: the fuzzy controller on e (eqs. (1), (2) of 002), the
    waist toward what it steers on, the estimate, the blind drive on, the back-off from a
    cylinder cut by the frame's border, ADJUST and LOST."""
    _approach_both(e0, dpx0, steps)


def test_the_back_off_of_002_from_a_cut_cylinder():
    """The cylinder's colour ROI cut by the frame's left border, its rings not measured, the
    estimate 200 mm from the waist: C and Python back off alike, stop, look again."""
    cut = {"double_cross": None, "red_cylinder": None, "red_roi": ROI.result_type()(
        u_c_q4=16 * 35, v_c_q4=16 * 150, roi=(0, 60, 70, 180), area_px=9000,
        touches_edge=False)}
    whole = {**cut, "red_roi": ROI.result_type()(u_c_q4=16 * 150, v_c_q4=16 * 120,
                                                 roi=(120, 60, 60, 120), area_px=6000,
                                                 touches_edge=False)}
    steps = [(20_000, cut, (-k * 6, 0, 0)) for k in range(26)] + [
        (20_000, None, (-150, 0, 0)), (40_000, whole, (-150, 0, 0)),
        (40_000, whole, (-150, 0, 0))]
    py = _approach_both(0, None, steps, obj=(200 + Task("002").p.mount_forward_mm, 0))
    assert py.ms.back_offs == 1 and py.ms.back_off is None and py.state == "ADJUST"


def test_the_board_alone_of_002():
    """The crosses ~1.1 m away in frame after frame, no red: C and Python count them alike and
    end FAILED "no graspable object found" at the same frame; red in a frame first, neither."""
    board = {"double_cross": CROSS.result_type()(u1_q4=0, v1_q4=0, u2_q4=0, v2_q4=0,
                                                 um_q4=16 * 160, vm_q4=16 * 120,
                                                 d_pixel_q4=16 * 40, e_mrad=0, votes=(1, 1)),
             "red_cylinder": None, "red_roi": None}
    steps = [(66_667, board, (k * 10, 0, 0)) for k in range(BOARD_ALONE_FRAMES + 2)]
    py = _approach_both(0, 40, steps)
    assert py.state == "FAILED" and py.failure.startswith("no graspable object found")
    red = {**board, "red_roi": ROI.result_type()(u_c_q4=16 * 155, v_c_q4=16 * 120,
                                                 roi=(150, 110, 10, 20), area_px=200,
                                                 touches_edge=True)}  # no range: no estimate
    py = _approach_both(0, 40, [(66_667, red, (0, 0, 0))] + steps)
    assert py.state == "APPROACH" and py.ms.red_seen


def test_the_look_back_of_002_after_the_sonar_guard():
    """Frames with nothing in them while the sonar guard drives out of R_r, then after it: C
    and Python hold the lost timeout alike, then turn in place back to the estimate until the
    base faces it, then count the lost timeout as before."""
    empty = {"double_cross": None, "red_cylinder": None, "red_roi": None}
    steps = [(66_667, empty, (0, 0, -120 * k)) for k in range(6)] + [
        (66_667, empty, (0, 0, -600 + 150 * k)) for k in range(6)] + [
        (500_000, empty, (0, 0, 300))] * 5
    wheels = []
    py = _approach_both(0, None, steps, obj=(900, 300), guarded=range(6), wheels=wheels)
    assert py.state == "LOST"
    turned = [w for w in wheels if w[0] == -w[1] != 0]
    assert turned and all(w[1] > 0 for w in turned)  # counter-clockwise, to the left


def _approach_both(e0, dpx0, steps, obj=None, guarded=(), wheels=None):
    """APPROACH of 002 on both (the search's sighting e0, dpx0; the object estimate obj, mm
    in the odometry frame, or none), step by step, every output compared; the Python task.
    In the steps ``guarded`` the sonar guard's drive out of R_r is under way; each step's
    wheels are appended to ``wheels``."""
    py, c = Task("002"), _c_task()
    if obj is not None:
        py.obj, c.has_obj, c.obj_mm = obj, 1, obj
    rules = Method002()
    py.ms.e_mrad, py.ms.e_dpx = e0, dpx0
    ms = _ms(c)
    ms.e_mrad, ms.has_e_dpx, ms.e_dpx = e0, dpx0 is not None, dpx0 or 0
    py.go(0, "APPROACH", "test")
    C.mg_task_go(c, 0, C.MG_APPROACH, b"test")
    rules.enter_approach(py, 0, TaskInputs())
    C.mg_method002_enter_approach(c, FFI.new("mg_task_inputs_t *"))
    has_u, u = FFI.new("int32_t *"), FFI.new("int32_t *")
    now = 0
    for k, (dt, dets, xyh) in enumerate(steps):
        now += dt
        py.guard_out = {"heading_mrad": 0} if k in guarded else None
        c.guard_out.active = int(k in guarded)
        py._events, py._detail, c.n_events = [], {}, 0
        inp = TaskInputs(x_mm=xyh[0], y_mm=xyh[1], heading_mrad=xyh[2], detections=dets or {})
        inp_c = FFI.new("mg_task_inputs_t *", _xyh(xyh))
        rules.approach(py, now, inp, dets or {})
        C.mg_method002_approach(c, now, inp_c, _frame002(dets), has_u, u)
        assert _events(c) == py._events
        assert (tuple(c.wheels), list(c.arm), c.move_done_us) == (py.wheels, py.arm,
                                                                  py.move_done_us)
        assert (tuple(c.obj_mm) if c.has_obj else None, c.obj_seen_us) == (py.obj,
                                                                         py.obj_seen_us)
        assert c.bad_detections == py.counters["bad_detections"]
        assert _blind(c) == py.ms.blind
        assert _back_off(c) == (py.ms.cut, py.ms.back_offs, py.ms.back_off)
        assert (bool(_ms(c).red_seen), _ms(c).alone_frames) == (py.ms.red_seen,
                                                               py.ms.alone_frames)
        assert bool(_ms(c).look_back) == py.ms.look_back
        if wheels is not None:
            wheels.append(py.wheels)
        assert (u[0] if has_u[0] else None) == py._detail.get("fuzzy", {}).get("u_mrad")
        if py.state != "APPROACH":
            break
        py.remember(now, inp)
        C.mg_task_remember(c, now, *xyh)
    return py


@SETTINGS
@given(st.tuples(NEAR, NEAR), st.tuples(*[ANGLE] * 4),
       st.lists(st.tuples(st.sampled_from([20_000, 40_000, 400_000, 1_500_000]),
                          st.none() | st.builds(
                              lambda u, v, d, w: RED(u_c_q4=u, v_c_q4=v, ring1_v_q4=0,
                                                     ring2_v_q4=d, d_pixel_q4=d, width_q4=w,
                                                     roi=(0, 0, 1, 1)),
                              PX_U, PX_V, st.integers(-16, 60 * 16), st.integers(1, 100 * 16)),
                          st.tuples(st.integers(-400, 400), st.integers(-400, 400),
                                    st.integers(-3142, 3141))), max_size=30))
def test_the_adjust_of_002(obj, joints, steps):
    """ADJUST: the close-look posture, the close approach on the estimate (eq. (8) of 000's
    wheels), the stop rule d_pixel > T_d, ROUGH_GRASP on the estimate or LOST."""
    py, c = Task("002"), _c_task()
    py.arm[2:6] = c.arm[2:6] = list(joints)
    py.obj, c.has_obj, c.obj_mm = obj, 1, obj
    py.go(0, "ADJUST", "test")
    C.mg_task_go(c, 0, C.MG_ADJUST, b"test")
    ADJUST.enter_ADJUST(py, 0, TaskInputs())
    C.mg_task_enter_adjust(c, 0)
    now = 0
    for dt, det, xyh in steps:
        now += dt
        py._events, c.n_events = [], 0
        inp = TaskInputs(x_mm=xyh[0], y_mm=xyh[1], heading_mrad=xyh[2])
        ADJUST.do_ADJUST(py, now, inp, {} if det is None else {"red_cylinder": det})
        seen = None if det is None else FFI.new("mg_red_cylinder_seen_t *", (
            det.u_c_q4, det.v_c_q4, det.d_pixel_q4, det.width_q4))
        C.mg_task_do_adjust(c, now, FFI.new("mg_task_inputs_t *", _xyh(xyh)),
                            seen if seen is not None else FFI.NULL, FFI.NULL)
        assert _events(c) == py._events
        assert (tuple(c.wheels), list(c.arm), c.move_done_us, c.trust_from_us) == (
            py.wheels, py.arm, py.move_done_us, py.trust_from_us)
        assert (tuple(c.obj_mm), c.obj_seen_us, c.bad_detections) == (
            py.obj, py.obj_seen_us, py.counters["bad_detections"])
        assert (machine.STATES[c.lost_in] if c.lost_in >= 0 else None) == py.lost_in
        if py.state != "ADJUST":
            break
        py.remember(now, inp)
        C.mg_task_remember(c, now, *xyh)


# --- sense.py ----------------------------------------------------------------------------------
JOINTS = st.tuples(st.integers(-200, 200), st.integers(-1600, 1600), *[ANGLE] * 4)
CAMS = st.sampled_from([sense.CAMERA_000, sense.CAMERA_002])


def _cam(cam):
    return FFI.new("mg_camera_model_t *", (cam.f_px, cam.u0_px, cam.v0_px))


@SETTINGS
@given(st.sampled_from([PAPER_000, PAPER_002]), JOINTS, CAMS,
       st.tuples(*[st.integers(-2000, 7000)] * 4), st.integers(-100, 5000),
       st.none() | st.integers(-400 * 16, 200 * 16))
def test_plus_positions(g, joints, cam, uv, dist_mm, top_q4):
    """Both "+" of a dual "+" in the platform frame, at its depth or on the top's plane."""
    det = registry.row("dual_plus").result_type()(*uv, 1, 1, dist_mm, dist_mm, 0, 0, 0)
    want = sense.plus_positions(det, g, joints, cam, top_q4)
    out = FFI.new("int32_t[2][3]")
    geom = FFI.new("mg_arm_geometry_t *", (g.l1_mm_q4, g.l2_mm_q4, g.l3_mm_q4))
    ok = C.mg_plus_positions(geom, joints, _cam(cam), uv, dist_mm, top_q4 is not None,
                             top_q4 or 0, out)
    assert (tuple(tuple(p) for p in out) if ok else None) == want


@SETTINGS
@given(st.sampled_from([PAPER_000, PAPER_002]), JOINTS, CAMS, st.integers(-2000, 7000),
       st.integers(-2000, 5000), st.integers(-100, 5000 * 16))
def test_pixel_to_platform(g, joints, cam, u_q4, v_q4, depth_q4):
    """The camera's axes and the pixel's ray (eqs. (1)-(3) of 000 with the wrist roll)."""
    axes, out = FFI.new("int32_t[3][3]"), FFI.new("int32_t[3]")
    C.mg_camera_axes_q12(joints, axes)
    assert tuple(tuple(a) for a in axes) == sense.camera_axes_q12(joints)
    geom = FFI.new("mg_arm_geometry_t *", (g.l1_mm_q4, g.l2_mm_q4, g.l3_mm_q4))
    C.mg_pixel_to_platform_mm_q4(geom, joints, _cam(cam), u_q4, v_q4, depth_q4, out)
    assert tuple(out) == sense.pixel_to_platform_mm_q4(g, joints, cam, u_q4, v_q4, depth_q4)


@SETTINGS
@given(st.integers(-2000, 7000), ANGLE, CAMS, st.integers(0, 5000))
def test_bearing_and_d_pixel(um_q4, theta5, cam, d_q4):
    cross = registry.row("double_cross").result_type()(
        u1_q4=0, v1_q4=0, u2_q4=0, v2_q4=0, um_q4=um_q4, vm_q4=0, d_pixel_q4=d_q4, e_mrad=0,
        votes=(1, 1))
    assert C.mg_bearing_mrad(um_q4, theta5, _cam(cam)) == sense.bearing_mrad(cross, theta5, cam)
    assert C.mg_d_pixel_px(d_q4) == sense.d_pixel_px(cross) == sense.d_pixel_px(_red(d_q4))


POS = st.integers(-10**6, 10**6)


@SETTINGS
@given(POS, POS, st.integers(-7000, 7000), st.integers(0, 300), st.tuples(POS, POS, POS), POS,
       POS)
def test_platform_and_odometry_frames(x, y, h, fwd, p_q4, ox, oy):
    out = FFI.new("int32_t[2]")
    C.mg_platform_to_odom_mm(x, y, h, fwd, p_q4, out)
    assert tuple(out) == sense.platform_to_odom_mm(x, y, h, fwd, p_q4)
    C.mg_odom_to_platform_q4(x, y, h, fwd, ox, oy, out)
    assert tuple(out) == sense.odom_to_platform_q4(x, y, h, fwd, ox, oy)


# --- the sequence of a shipped scenario -------------------------------------------------------
def recorder(mp, calls: list):
    """``wrap(cls, name, before, after, quiet=False)``: each call of ``cls.name`` recorded in
    ``calls`` as ``before(*args)`` (None: not recorded) + ``after(result, *args)``; the calls a
    quiet unit makes itself are part of its record, not their own."""
    inside = []

    def wrap(cls, name, before, after, quiet=False):
        orig = getattr(cls, name)

        def recorded(*a, **kw):
            if inside:
                return orig(*a, **kw)
            rec = before(*a, **kw)
            inside.extend([1] if quiet else [])
            try:
                res = orig(*a, **kw)
            finally:
                del inside[:int(quiet)]
            if rec is not None:
                calls.append(rec + after(res, *a, **kw))
            return res
        mp.setattr(cls, name, recorded)
    return wrap


def _record(mp, calls: list, steps: bool = False) -> None:
    """Wrap the Python task's units so that each call is recorded with what it read and gave.
    steps: record the APPROACH steps whole (and what keeps the C's history and fuzzy approach
    in step)."""
    wrap = recorder(mp, calls)
    if steps:
        wrap(machine.Task, "remember",
             lambda t, now, inp: ("remember", now, (inp.x_mm, inp.y_mm, inp.heading_mrad),
                                  list(t.arm)),
             lambda res, t, *a: (len(t.arm_hist), len(t.pose_hist)))
        wrap(Method002, "enter_approach",
             lambda rules, t, now, inp: ("enter_approach", (inp.x_mm, inp.y_mm,
                                                            inp.heading_mrad),
                                         t.ms.e_mrad, t.ms.e_dpx, t.ms.e_range_mm),
             lambda res, rules, t, *a: (t.ms.blind,), quiet=True)

        def approach_before(rules, t, now, inp, dets):
            t._detail.pop("fuzzy", None)
            return ("approach", now, (inp.x_mm, inp.y_mm, inp.heading_mrad), dict(dets),
                    list(t.arm), t.move_done_us, t.obj, t.obj_seen_us, t.trust_from_us,
                    t.state, t.counters["bad_detections"])
        wrap(AdjustState, "enter_ADJUST",
             lambda adj, t, now, inp: ("enter_adjust", now, list(t.arm), t.move_done_us,
                                       t.obj_seen_us),
             lambda res, adj, t, *a: (list(t.arm), t.move_done_us, t.trust_from_us,
                                      t.obj_seen_us), quiet=True)
        wrap(AdjustState, "do_ADJUST",
             lambda adj, t, now, inp, dets: (
                 "adjust", now, (inp.x_mm, inp.y_mm, inp.heading_mrad),
                 dets.get("red_cylinder"), list(t.arm), t.move_done_us, t.obj, t.obj_seen_us,
                 t.trust_from_us),
             lambda res, adj, t, *a: (list(t._events), t.wheels, list(t.arm), t.move_done_us,
                                      t.obj, t.obj_seen_us), quiet=True)
        # the machine's tables hold ADJUST's methods bound at import: through the class now
        mp.setitem(machine.ENTRY, "ADJUST", lambda *a: ADJUST.enter_ADJUST(*a))
        mp.setitem(machine.STEP, "ADJUST", lambda *a: ADJUST.do_ADJUST(*a))
        wrap(Method002, "approach", approach_before,
             lambda res, rules, t, *a: (list(t._events), t.wheels, list(t.arm), t.move_done_us,
                                        t.obj, t.obj_seen_us, t.ms.blind,
                                        t.counters["bad_detections"],
                                        t._detail.get("fuzzy", {}).get("u_mrad")), quiet=True)
        return
    wrap(machine.Task, "set_arm",
         lambda t, now, th2, th3, th4, th5, th1=None: (
             "arm", now, (th2, th3, th4, th5, th1), list(t.arm), t.move_done_us),
         lambda res, t, *a, **kw: (list(t.arm), t.move_done_us))
    wrap(machine.Task, "remember",
         lambda t, now, inp: ("remember", now, (inp.x_mm, inp.y_mm, inp.heading_mrad),
                              list(t.arm)),
         lambda res, t, *a: (len(t.arm_hist), len(t.pose_hist)))
    for name in ("arm_at", "pose_at"):
        wrap(machine.Task, name, lambda t, t_us, name=name: (name, t_us),
             lambda res, *a: (res,))
    wrap(machine.Task, "go", lambda t, now, to, why: ("go", now, to, why),
         lambda res, *a: ())
    wrap(Method002, "enter_approach",
         lambda rules, t, now, inp: ("enter_approach", (inp.x_mm, inp.y_mm, inp.heading_mrad),
                                     t.ms.e_mrad, t.ms.e_dpx, t.ms.e_range_mm),
         lambda res, rules, t, *a: (t.ms.blind,), quiet=True)
    wrap(Method002, "found",
         lambda rules, t, now, inp, name, det: ("found", now, name, det),
         lambda res, rules, t, *a: (res, t.ms.e_mrad, t.obj_seen_us, t.ms.e_dpx,
                                    t.ms.e_range_mm, rules.found_why(t)), quiet=True)
    wrap(machine.Task, "see_object",
         lambda t, now, inp, name, det: None if name != "red_cylinder" else (
             "see", now, (det.u_c_q4, det.v_c_q4, det.d_pixel_q4, det.width_q4),
             (inp.x_mm, inp.y_mm, inp.heading_mrad), t.trust_from_us),
         lambda res, t, *a: (res, t.obj, t.obj_seen_us), quiet=True)
    wrap(machine.Task, "look_at_object",
         lambda t, inp, top=True: ("look", (inp.x_mm, inp.y_mm, inp.heading_mrad), top,
                                   list(t.arm), t.obj),
         lambda res, t, *a, **kw: (list(t.arm),))
    wrap(Method002, "remember_bearing",
         lambda rules, t, inp, e, cue: ("bearing", (inp.x_mm, inp.y_mm, inp.heading_mrad), e,
                                        cue),
         lambda res, rules, t, *a: (t.ms.blind,))
    wrap(FuzzyApproach, "step", lambda f, t_us, e, d=None: ("fuzzy", t_us, e, d),
         lambda res, *a: ((res.left_mm_s, res.right_mm_s, res.u_mrad, res.stop),))

    wrap(Method002, "track_marker",
         lambda rules, t, now, vm, e: ("track", now, vm, e, list(t.arm), t.move_done_us),
         lambda res, rules, t, *a: (list(t.arm), t.move_done_us))
    wrap(Method002, "adjust_done",
         lambda rules, t, now, det, dist: (
             "stop", now, det.d_pixel_q4 if isinstance(det, RED) else None, dist,
             t.trust_from_us),
         lambda res, rules, t, *a: (res, t.state, t._events[-1].why if res else None),
         quiet=True)

    def blind_before(rules, t, now, inp):
        t._detail.pop("fuzzy", None)
        return ("blind", now, (inp.x_mm, inp.y_mm, inp.heading_mrad), list(t.arm),
                t.move_done_us, t.obj_seen_us, t.ms.blind)
    wrap(Method002, "approach_blind", blind_before,
         lambda res, rules, t, *a: (res, t.wheels, list(t.arm), t.move_done_us,
                                    t._detail.get("fuzzy", {}).get("u_mrad")), quiet=True)


def _xyh(xyh: tuple) -> dict:
    return dict(zip(("x_mm", "y_mm", "heading_mrad"), xyh, strict=True))


def replay_remember(c, rec: tuple) -> None:
    """A recorded ``remember`` (the arm it kept, the history's lengths after) on the C task."""
    _, now, xyh, pre, n_arm, n_pose = rec
    c.arm[0:6] = pre
    C.mg_task_remember(c, now, *xyh)
    assert (c.n_arm_hist, c.n_pose_hist) == (n_arm, n_pose), rec


def _replay(c, calls: list) -> dict:
    """Each recorded call on the C task, with the state the Python call read; what it gave
    compared. The count of calls of each kind."""
    counts: dict = {}
    ms = _ms(c)
    arm, at, pose = FFI.new("int32_t[6]"), FFI.new("int64_t *"), FFI.new("int32_t[3]")
    u = FFI.new("int32_t *")
    for rec in calls:
        kind = rec[0]
        counts[kind] = counts.get(kind, 0) + 1
        if kind == "arm":
            _, now, (th2, th3, th4, th5, th1), pre, done, post, post_done = rec
            _load(c, pre, done)
            C.mg_task_set_arm(c, now, th2, th3, th4, th5, th1 is not None, th1 or 0)
            assert (list(c.arm), c.move_done_us) == (post, post_done), rec
        elif kind == "remember":
            replay_remember(c, rec)
        elif kind == "arm_at":
            C.mg_task_arm_at(c, rec[1], arm)
            assert tuple(arm) == rec[2], rec
        elif kind == "pose_at":
            assert C.mg_task_pose_at(c, rec[1], at, pose) == 1
            assert (at[0], *pose) == rec[2], rec
        elif kind == "go":
            _, now, to, why = rec
            c.n_events = 0
            C.mg_task_go(c, now, machine.STATES.index(to), why.encode())
            assert _events(c)[0].why == why and c.entered_us == now
        elif kind == "track":
            _, now, vm, e, pre, done, post, post_done = rec
            _load(c, pre, done)
            C.mg_method002_track_marker(c, now, vm is not None, vm or 0, e)
            assert (list(c.arm), c.move_done_us) == (post, post_done), rec
        elif kind == "stop":
            _, now, d_q4, dist, trust, res, state, why = rec
            c.trust_from_us, c.n_events = trust, 0
            assert C.mg_method002_adjust_done(c, now, d_q4 is not None, d_q4 or 0, dist) == res
            assert machine.STATES[c.state] == state, rec
            assert [e.why for e in _events(c)] == ([why] if res else []), rec
        elif kind == "enter_approach":
            _, xyh, e, dpx, e_range, blind = rec
            ms.e_mrad, ms.has_e_dpx, ms.e_dpx = e, dpx is not None, dpx or 0
            ms.has_e_range, ms.e_range_mm = e_range is not None, e_range or 0
            C.mg_method002_enter_approach(c, FFI.new("mg_task_inputs_t *", _xyh(xyh)))
            assert _blind(c) == blind, rec
        elif kind == "found":
            _, now, name, det, res, e, seen, dpx, e_range, found_why = rec
            assert res
            assert C.mg_method002_found(c, now, FFI.new("mg_sighting002_t *",
                                                        _sighting(name, det)))
            assert (ms.e_mrad, c.obj_seen_us) == (e, seen), rec
            assert (ms.e_dpx if ms.has_e_dpx else None) == dpx, rec
            assert (ms.e_range_mm if ms.has_e_range else None) == e_range, rec
            why = FFI.new("char[]", WHY_BYTES)
            C.mg_method002_found_why(c, why, WHY_BYTES)
            assert FFI.string(why).decode() == found_why
        elif kind == "see":
            _, now, det, xyh, trust, res, obj, seen = rec
            c.trust_from_us = trust
            assert C.mg_task_see_object(
                c, now, FFI.new("mg_task_inputs_t *", _xyh(xyh)),
                FFI.addressof(C, "mg_method002_red_cylinder_position"),
                FFI.new("mg_red_cylinder_seen_t *", det), 1) == res, rec
            if res:
                assert (tuple(c.obj_mm), c.obj_seen_us) == (obj, seen), rec
        elif kind == "approach":
            (_, now, xyh, dets, pre, done, obj, seen, trust, state, bad, events, wheels, post,
             post_done, post_obj, post_seen, blind, post_bad, u_mrad) = rec
            _load(c, pre, done)
            c.has_obj, c.obj_mm = obj is not None, obj or (0, 0)
            c.obj_seen_us, c.trust_from_us = seen, trust
            c.state, c.n_events, c.bad_detections = machine.STATES.index(state), 0, bad
            has_u = FFI.new("int32_t *")
            C.mg_method002_approach(c, now, FFI.new("mg_task_inputs_t *", _xyh(xyh)),
                                    _frame002(dets), has_u, u)
            assert _events(c) == events, rec
            assert (tuple(c.wheels), list(c.arm), c.move_done_us) == (wheels, post,
                                                                      post_done), rec
            assert (tuple(c.obj_mm) if c.has_obj else None, c.obj_seen_us) == (post_obj,
                                                                             post_seen), rec
            assert (_blind(c), c.bad_detections) == (blind, post_bad), rec
            assert (u[0] if has_u[0] else None) == u_mrad, rec
        elif kind == "enter_adjust":
            _, now, pre, done, seen, post, post_done, trust, post_seen = rec
            _load(c, pre, done)
            c.obj_seen_us = seen
            C.mg_task_enter_adjust(c, now)
            assert (list(c.arm), c.move_done_us, c.trust_from_us, c.obj_seen_us) == (
                post, post_done, trust, post_seen), rec
        elif kind == "adjust":
            (_, now, xyh, det, pre, done, obj, seen, trust, events, wheels, post, post_done,
             post_obj, post_seen) = rec
            _load(c, pre, done)
            c.has_obj, c.obj_mm = obj is not None, obj or (0, 0)
            c.obj_seen_us, c.trust_from_us, c.n_events = seen, trust, 0
            c.state = C.MG_ADJUST
            C.mg_task_do_adjust(c, now, FFI.new("mg_task_inputs_t *", _xyh(xyh)),
                                FFI.NULL if det is None else FFI.new(
                                    "mg_red_cylinder_seen_t *", (det.u_c_q4, det.v_c_q4,
                                                                 det.d_pixel_q4, det.width_q4)),
                                FFI.NULL)
            assert _events(c) == events, rec
            assert (tuple(c.wheels), list(c.arm), c.move_done_us) == (wheels, post,
                                                                      post_done), rec
            assert (tuple(c.obj_mm), c.obj_seen_us) == (post_obj, post_seen), rec
        elif kind == "look":
            _, xyh, top, pre, obj, post = rec
            c.arm[0:6], c.has_obj, c.obj_mm = pre, obj is not None, obj or (0, 0)
            C.mg_task_look_at_object(c, FFI.new("mg_task_inputs_t *", _xyh(xyh)), top)
            assert list(c.arm) == post, rec
        elif kind == "bearing":
            _, xyh, e, cue, blind = rec
            inp = FFI.new("mg_task_inputs_t *", _xyh(xyh))
            C.mg_method002_remember_bearing(c, inp, e, cue is not None, cue or 0)
            assert _blind(c) == blind, rec
        elif kind == "fuzzy":
            _, t_us, e, d, cmd = rec
            got = C.mg_fuzzy_approach_step(FFI.addressof(ms, "fuzzy"), t_us, e is not None,
                                           e or 0, d is not None, d or 0)
            assert (got.left_mm_s, got.right_mm_s, got.u_mrad, bool(got.stop)) == cmd, rec
        else:
            _, now, xyh, pre, done, seen, blind, res, wheels, post, post_done, u_mrad = rec
            _load(c, pre, done)
            c.obj_seen_us = seen
            assert _blind(c) == blind, rec
            inp = FFI.new("mg_task_inputs_t *", _xyh(xyh))
            assert C.mg_method002_approach_blind(c, now, inp, u) == res, rec
            if res:
                assert (tuple(c.wheels), list(c.arm), c.move_done_us, u[0]) \
                    == (wheels, post, post_done, u_mrad), rec
    assert c.hist_overflow == 0 and c.events_lost == 0
    return counts


def recorded_runs(tmp_path, scenario: str, recorders: dict) -> dict[str, list]:
    """A shipped scenario run once in process (it must succeed) with every ``record(mp,
    calls)`` of ``recorders`` attached, each filling its own list; a record may return a
    context manager held open during the run (a planner watcher). The lists by name."""
    from mobigrasp.services.run_job import RunOptions, execute
    calls: dict[str, list] = {name: [] for name in recorders}
    with pytest.MonkeyPatch.context() as mp, contextlib.ExitStack() as stack:
        for name, record in recorders.items():
            watcher = record(mp, calls[name])
            if watcher is not None:
                stack.enter_context(watcher)
        summary, code = execute(RunOptions(scenario=scenario, transport="inproc",
                                           out=tmp_path / "run", progress=False, plots=False))
    assert code == 0 and summary["success"], summary
    return calls


def recorded_run(tmp_path, scenario: str, record) -> list:
    """The calls ``record(mp, calls)`` records of the Python task in a shipped scenario, run in
    process (it must succeed)."""
    return recorded_runs(tmp_path, scenario, {"calls": record})["calls"]


def record002(mp, calls: list) -> None:
    """A recorder (``recorded_runs``) of method 002's calls (``_record``)."""
    _record(mp, calls)


def record002_approach(mp, calls: list) -> None:
    """A recorder of method 002's APPROACH and ADJUST steps whole (``_record`` with steps)."""
    _record(mp, calls, steps=True)


def test_replay_of_paper002_marker(shared_recording):
    """The calls the Python task made in paper002-marker replayed on the C task with the same
    inputs: the same outputs, call by call."""
    calls = shared_recording("paper002-marker", "calls")
    counts = _replay(_c_task(), calls)
    assert any(r[0] == "stop" and r[5] for r in calls)  # the stop rule ended ADJUST
    for kind in ("arm", "remember", "arm_at", "go", "enter_approach", "bearing", "fuzzy",
                 "track", "stop", "look", "found", "see"):
        assert counts.get(kind, 0) > 0, (kind, counts)


def test_replay_of_the_approach_of_paper002_marker(shared_recording):
    """APPROACH's and ADJUST's steps in paper002-marker, each with the frame's results, on the
    C task."""
    calls = shared_recording("paper002-marker", "approach")
    counts = _replay(_c_task(), calls)
    assert counts.get("approach", 0) > 20 and counts.get("adjust", 0) > 5, counts
    ended = [r for r in calls if r[0] == "approach" and r[11]]
    assert [e.to_state for e in ended[-1][11]] == ["ADJUST"]
    stopped = [r for r in calls if r[0] == "adjust" and r[9]]
    assert [e.to_state for e in stopped[-1][9]] == ["ROUGH_GRASP"]
