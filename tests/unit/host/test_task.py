"""host/task: transitions on scripted inputs, timeouts, LOST, bad inputs, all in simulated time."""

import detections as det
import pytest

from mobigrasp.host import arm_calib
from mobigrasp.host.planning.anytime import PLAN_SLICE_US
from mobigrasp.host.task import DEFAULT_TIMEOUTS_US, STATES, Task, TaskInputs, TaskParams

# a radial symbol straight ahead of the camera in the search posture (alpha near 0), 1 m away
RADIAL_AHEAD = det.radial(160 * 16, 150 * 16, 1000)


def step(task, t_us, **kw):
    out = task.step(t_us, TaskInputs(**kw))
    for ch, a in enumerate(out.servo_mrad):
        assert arm_calib.within_limits(ch, a)
    return out


def test_starts_in_search_and_asks_for_the_search_detector():
    # 000's and 001's SEARCH look for the symbol cut by the frame where they read none (the
    # back-off)
    for method in ("000", "001"):
        assert Task(method).detectors_needed() == ["radial_symbol", "radial_cut"]
        assert Task(method).detector_fallbacks() == {"radial_cut": "radial_symbol"}
    assert Task("002").detectors_needed() == ["double_cross", "red_roi"]
    out = step(Task("000"), 0)
    assert out.state == "SEARCH" and out.events == [] and out.wheels_mmps == (0, 0)


def find(task, t, name, det, **kw):
    """Feed the same detection every frame (every 3rd step) until the task leaves SEARCH."""
    k = 0
    while task.state == "SEARCH":
        out = step(task, t, detections={name: det} if k % 3 == 0 else {}, **kw)
        t += 20_000
        k += 1
        assert t < 5_000_000
    return out, t


def test_found_is_confirmed_then_approach_with_a_logged_event_and_a_plan():
    task = Task("000")
    step(task, 0)
    out = step(task, 40_000)
    assert out.state == "SEARCH"
    out = step(task, 60_000, detections={"radial_symbol": RADIAL_AHEAD})
    assert out.state == "SEARCH" and "search_seen" in out.detail  # holds the pose, looks again
    held = out.servo_mrad
    out = step(task, 80_000, detections={"radial_symbol": RADIAL_AHEAD})
    assert out.state == "SEARCH" and out.servo_mrad == held  # not yet settled: not trusted
    out, t = find(task, 100_000, "radial_symbol", RADIAL_AHEAD)
    assert out.state == "APPROACH"
    (ev,) = out.events
    assert (ev.from_state, ev.to_state) == ("SEARCH", "APPROACH") and ev.t_us == t - 20_000
    assert "radial symbol" in ev.why and "confirmed" in ev.why
    # the object sits about 1 m ahead of the base
    assert 900 < task.obj[0] < 1300 and abs(task.obj[1]) < 150
    out = step(task, t)
    plan_us = out.detail["plan"]["plan_arm9_us"]
    assert out.detail["plan"]["feasible"] > 0  # planning charged, its first slice in this step
    assert min(plan_us, PLAN_SLICE_US) <= out.ops.time_us() <= PLAN_SLICE_US + 1000
    # the path is taken in the step of the plan's last slice; the base stands before it
    slices = -(-plan_us // PLAN_SLICE_US)
    for k in range(1, slices):
        assert out.wheels_mmps == (0, 0)
        out = step(task, t + 20_000 * k)
    out = step(task, t + 20_000 * slices)
    assert out.wheels_mmps != (0, 0)
    assert task.detectors_needed() == ["radial_symbol"]


def test_a_not_found_result_does_not_trigger():
    task = Task("000")
    out = step(task, 0, detections={"radial_symbol": None})
    assert out.state == "SEARCH"


def test_unconfirmed_sighting_resumes_the_search():
    """A sighting the held pose does not read again is dropped and the pattern goes on (with
    the drive to a far sighting off: 000's drive to one is tested in test_search_wander.py)."""
    task = Task("000", {"sighting_approach_mm": 0})
    step(task, 0)
    step(task, 80_000)
    out = step(task, 100_000, detections={"radial_symbol": RADIAL_AHEAD})
    assert "search_seen" in out.detail
    held = out.servo_mrad
    t = 120_000
    while t < 3_000_000:
        out = step(task, t, detections={"radial_symbol": None})
        if out.servo_mrad != held:
            break
        t += 20_000
    assert task.state == "SEARCH" and out.servo_mrad != held
    assert t >= 100_000 + task.p.confirm_us  # held at least the confirmation time


def test_search_sweeps_the_waist_and_turns_the_base_after_a_cycle():
    task = Task("000", {"search": {"theta2_min_mrad": -2200, "theta2_max_mrad": -2100}})
    waist, wheels = set(), set()
    heading = 0
    t = 0
    turned = False
    while t < 60_000_000 and not turned:
        out = step(task, t, heading_mrad=heading)
        waist.add(out.servo_mrad[5])
        if out.wheels_mmps != (0, 0):
            wheels.add(out.wheels_mmps)
            heading += 30  # the base turns counter-clockwise under the test's feet
            # the camera looks as it turns
            assert task.detectors_needed() == ["radial_symbol", "radial_cut"]
        turned = any(d == "base_turn_mrad" for d in out.detail) or turned
        t += 20_000
    assert min(waist) == -800 and max(waist) == 800
    assert wheels == {(-80, 80)}  # counter-clockwise turn in place
    for _ in range(200):  # finish the 60 degree turn, then the search resumes
        out = step(task, t, heading_mrad=heading)
        if out.wheels_mmps == (0, 0):
            break
        heading += 30
        t += 20_000
    assert heading >= 1047 and out.wheels_mmps == (0, 0) and task.state == "SEARCH"


def test_search_timeout_fails_with_reason():
    task = Task("000", {"timeouts_us": {"SEARCH": 1_000_000}})
    step(task, 0)
    assert step(task, 999_999).state == "SEARCH"
    out = step(task, 1_000_000)
    assert out.state == "FAILED" and out.wheels_mmps == (0, 0)
    assert out.events[0].to_state == "FAILED" and "timeout" in out.events[0].why
    assert "SEARCH" in task.failure
    assert step(task, 2_000_000).state == "FAILED"  # terminal


def to_adjust(task, t=0):
    step(task, t)
    _, t = find(task, t + 20_000, "radial_symbol", RADIAL_AHEAD)
    step(task, t)
    task.go(t + 20_000, "ADJUST", "test: skip the path")
    step(task, t + 20_000)
    assert task.state == "ADJUST"
    return t + 20_000


def test_lost_in_adjust_goes_lost_then_search():
    task = Task("000")
    assert task.detector_fallbacks() == {"radial_cut": "radial_symbol"}  # SEARCH
    t0 = to_adjust(task)
    assert task.detectors_needed() == ["dual_plus", "radial_symbol"]
    # ADJUST reads the rings only on frames without the dual "+" (host/app.py runs it so)
    assert task.detector_fallbacks() == {"radial_symbol": "dual_plus"}
    t = t0
    state = "ADJUST"
    while state == "ADJUST":
        t += 20_000
        out = step(task, t, detections={"dual_plus": None})  # frames without the object
        state = out.state
    assert state == "LOST"
    assert out.events[-1].from_state == "ADJUST" and "not seen" in out.events[-1].why
    assert t - task.obj_seen_us >= task.p.lost_timeout_us
    assert out.wheels_mmps == (0, 0)
    t_lost = t
    while state == "LOST":
        t += 20_000
        out = step(task, t)
        state = out.state
    assert state == "SEARCH" and t - t_lost >= task.p.lost_hold_us
    assert task.counters["lost"] == 1


def test_too_many_losses_fail():
    task = Task("000", {"max_lost": 0})
    to_adjust(task)
    t = 100_000
    while task.state not in ("FAILED",) and t < 10_000_000:
        step(task, t, detections={"dual_plus": None})
        t += 20_000
    assert task.state == "FAILED" and "lost" in task.failure


def test_grasp_closed_then_lift_without_evidence_grasps_again_and_drop_fails():
    """Nothing seen after the lift is no evidence of holding: open and ADJUST, never DONE."""
    for drop in (False, True):
        task = Task("000")
        task.go(0, "PRECISE_GRASP", "test")
        task.grasp_alpha = -1571
        task.arm = [0, 0, -1324, -1216, 969, 0]
        task.phase, task.gripper = "close", 1000
        task.entry_pending = False
        task.phase_us = 0
        out = step(task, 20_000, grasp_closed=True)
        assert out.state == "LIFT" and out.events[-1].why == "gripper closed on the object"
        t = 20_000
        while task.state == "LIFT":
            t += 20_000
            out = step(task, t, grasp_closed=not (drop and t > 100_000))
        assert out.state == ("FAILED" if drop else "ADJUST")
        if drop:
            assert "dropped" in task.failure
        else:
            assert "no evidence" in out.events[-1].why
            assert out.gripper_permille == 0 and out.servo_mrad[0] == 0


def _missed_without_evidence(task, close_by=None, t: int = 20_000) -> int:
    """From the close (decided by ``close_by``) to the grasp check's miss with nothing seen
    after the lift; the time."""
    task.go(0, "PRECISE_GRASP", "test")
    task.grasp_alpha = -1571
    task.arm = [0, 0, -1324, -1216, 969, 0]
    task.phase, task.gripper, task.close_by = "close", 1000, close_by
    task.entry_pending = False
    task.phase_us = 0
    while task.state in ("PRECISE_GRASP", "LIFT"):
        step(task, t, grasp_closed=True)
        t += 20_000
    assert task.state == "ADJUST" and "no evidence" in task._events[-1].why
    return t


@pytest.mark.parametrize("method", ["000", "002"])
@pytest.mark.parametrize("seen_since", [False, True])
def test_a_grasp_again_after_no_evidence_goes_only_on_a_new_sighting(method, seen_since):
    """A grasp whose check found no evidence, the object seen before it: the next grasp at the
    same estimate, the camera not having seen the object since, would be the same blind grasp:
    the task searches (LOST) instead; seen since (a new estimate), it grasps again."""
    task = Task(method)
    task.obj = (300, 0)
    task.graspable_seen = task.object_sighted = True
    t = _missed_without_evidence(task, "no_spoke" if method == "000" else None)
    assert task.regrasps == 1 and not task.object_sighted  # the sighting before counts no more
    task.object_sighted = seen_since  # as a sighting in ADJUST would set it
    task.go(t, "ROUGH_GRASP", "test")
    out = step(task, t + 20_000)
    if seen_since:  # the grasp goes on (here 000's rough pose out of reach: ADJUST first)
        assert out.state == ("ADJUST" if method == "000" else "ROUGH_GRASP"), out.events
    else:
        assert out.state == "LOST" and task.lost_in == "ROUGH_GRASP"
        assert out.events[-1].why.startswith("grasp missed at the estimate, object not seen since")


@pytest.mark.parametrize("close_by, blind", [(None, True), ("no_spoke", True),
                                             ("precise", False), ("max_steps", False),
                                             ("ik", False)])
def test_only_a_blind_grasp_without_evidence_drops_the_sighting(close_by, blind):
    """A close decided on the camera's view of the object where the fingers went (the spoke,
    001's look) keeps the sighting after a miss with no evidence; a blind one drops it."""
    task = Task("000")
    task.obj = (300, 0)
    task.graspable_seen = task.object_sighted = True
    _missed_without_evidence(task, close_by)
    assert task.object_sighted != blind


def test_gripper_that_closes_on_nothing_fails():
    task = Task("000")
    task.go(0, "PRECISE_GRASP", "test")
    task.phase, task.entry_pending, task.phase_us = "close", False, 0
    out = step(task, 20_000)
    assert out.state == "PRECISE_GRASP"
    out = step(task, task.p.grasp_close_timeout_us)
    assert out.state == "FAILED" and "no object" in task.failure


def test_bad_inputs_are_counted_and_dropped():
    task = Task("000")
    out = step(task, 0, joints_mrad=(1, 2, 3))
    assert out.state == "SEARCH" and task.counters["bad_inputs"] == 1
    out = step(task, 20_000, joints_mrad=("a",) * 6)
    assert task.counters["bad_inputs"] == 2
    out = step(task, 40_000, detections=None)
    assert task.counters["bad_inputs"] == 3 and out.state == "SEARCH"
    # another detector's result under the radial symbol's name, an untyped bag of fields
    out = step(task, 60_000, detections={"radial_symbol": det.spoke(0, 16)})
    assert out.state == "SEARCH" and task.counters["bad_detections"] == 1
    out = step(task, 70_000, detections={"radial_symbol": {"u_q4": 2560, "v_q4": 1920,
                                                           "y_oc_mm": 1000}})
    assert out.state == "SEARCH" and task.counters["bad_detections"] == 2
    out = step(task, 80_000, detections={"radial_symbol": det.radial(2560, 1920, 0)})  # no depth
    assert out.state == "SEARCH" and task.counters["bad_detections"] == 3


def test_step_needs_task_inputs():
    with pytest.raises(TypeError, match="TaskInputs"):
        Task("000").step(0, {"detections": {}})


def test_params_validation_and_method_defaults():
    with pytest.raises(ValueError, match="unknown task parameter 'nope'"):
        Task("000", {"nope": 1})
    with pytest.raises(ValueError, match="unknown state"):
        Task("000", {"timeouts_us": {"WALK": 1}})
    with pytest.raises(ValueError, match="must be an int"):
        Task("000", {"hover_mm": 1.5})
    with pytest.raises(ValueError, match="method"):
        Task("003")
    with pytest.raises(ValueError, match="link_lengths"):
        Task("000", link_lengths_mm=(1, 2))
    p = TaskParams.for_method("001")
    assert p.h_shoulder_mm == 108
    assert TaskParams.for_method("000", {"timeouts_us": {"LIFT": 5}}).timeouts_us == {
        **DEFAULT_TIMEOUTS_US, "LIFT": 5}
    assert set(DEFAULT_TIMEOUTS_US) <= set(STATES)


def test_002_search_then_fuzzy_approach_turns_toward_the_marker():
    task = Task("002")
    step(task, 0)
    # the double cross left of the image centre: e < 0 (left), the platform turns left
    dc = det.double_cross(100 * 16, 120 * 16)
    out, t = find(task, 20_000, "double_cross", dc)
    assert out.state == "APPROACH" and "e = " in out.events[0].why
    out = step(task, t, detections={"double_cross": dc, "red_cylinder": None})
    left, right = out.wheels_mmps
    assert right > left > 0
    assert out.detail["fuzzy"]["e_mrad"] < 0 and out.detail["fuzzy"]["u_mrad"] < 0
    assert task.detectors_needed() == ["double_cross", "red_cylinder", "red_roi"]
    # no new frame: the wheels are held, not re-decided
    assert step(task, t + 20_000).wheels_mmps == (left, right)


def _adjust_002(params=None):
    """002 in ADJUST, the cylinder estimated 500 mm ahead of the waist, after the entry's
    swing to the look; returns the task and the first time a frame counts."""
    task = Task("002", params)
    task.obj, task.obj_seen_us = (600, 0), 0
    task.go(0, "ADJUST", "test")
    out = step(task, 20_000, detections={"red_cylinder": None})
    assert out.state == "ADJUST" and out.wheels_mmps[0] > 0 and out.wheels_mmps[1] > 0
    return task, task.trust_from_us + task.p.frame_latency_us


def test_002_adjust_stops_by_the_stop_rule_d_pixel_over_t_d():
    task, t_ok = _adjust_002()
    rc = det.red_cylinder(160 * 16, 120 * 16, 46 * 16)
    out = step(task, t_ok - 20_000, detections={"red_cylinder": rc})
    assert out.state == "ADJUST"  # taken while the arm swung to the look: does not count
    rc = det.red_cylinder(160 * 16, 120 * 16, 44 * 16)
    assert step(task, t_ok, detections={"red_cylinder": rc}).state == "ADJUST"
    rc = det.red_cylinder(160 * 16, 120 * 16, 45 * 16 + 2)
    out = step(task, t_ok + 20_000, detections={"red_cylinder": rc})
    assert out.state == "ROUGH_GRASP" and out.wheels_mmps == (0, 0)
    assert "stop rule d_pixel > T_d" in out.events[0].why and "T_d = 45 px" in out.events[0].why


def test_002_t_d_is_a_parameter_that_decides_the_stop():
    task, t_ok = _adjust_002({"t_d_px": 50})
    rc = det.red_cylinder(160 * 16, 120 * 16, 46 * 16)
    assert step(task, t_ok, detections={"red_cylinder": rc}).state == "ADJUST"
    rc = det.red_cylinder(160 * 16, 120 * 16, 51 * 16)
    out = step(task, t_ok + 20_000, detections={"red_cylinder": rc})
    assert out.state == "ROUGH_GRASP" and "T_d = 50 px" in out.events[0].why


def test_001_with_a_given_object_position_plans_at_once():
    task = Task("001", {"object_xy_mm": [1500, 300]})
    out = step(task, 0, sonar_mm=(2500,) * 5)
    assert out.state == "APPROACH" and "given" in out.events[0].why
    out = step(task, 20_000, sonar_mm=(2500,) * 5)
    assert "plan" not in out.detail and out.wheels_mmps == (0, 0)  # one sonar sweep first
    out = step(task, 20_000 + task.p.sonar_sweep_us, sonar_mm=(2500,) * 5)
    assert out.detail["plan"]["planner"] == "001" and out.wheels_mmps != (0, 0)
    with pytest.raises(ValueError, match="object_xy_mm"):
        Task("001", {"object_xy_mm": [1.5, 0.3]})


def test_001_replans_when_the_sonar_sees_the_path_blocked():
    task = Task("001", {"object_xy_mm": [2500, 0], "sonar_sweep_us": 0})
    clear = (2500,) * 5
    step(task, 0, sonar_mm=clear)
    out = step(task, 20_000, sonar_mm=clear)
    assert out.detail["plan"]["feasible"] > 0
    t, x = 40_000, 0
    while t < 300_000:  # path clear: no replan
        out = step(task, t, x_mm=x, v_mmps=200, sonar_mm=clear)
        assert "replan" not in out.detail
        t += 20_000
        x += 4
    blocked = (2500, 2500, 600, 2500, 2500)  # an obstacle 0.6 m straight ahead (S_3)
    seen = []
    while t < 1_500_000 and not seen:
        out = step(task, t, x_mm=x, v_mmps=200, sonar_mm=blocked)
        if "replan" in out.detail:
            seen.append(out.detail["replan"])
        t += 20_000
    assert seen and seen[0].startswith("blocked")
    assert 0 < out.ops.time_us() <= PLAN_SLICE_US + 1000  # the check and a slice of the plan


def test_001_planner_gets_the_sonar_mount_and_shared_echo_tolerance():
    from mobigrasp.host.task.method001 import planner_params_001

    p = TaskParams.for_method("001", {"sonar_offset_mm": 170, "sonar_shared_echo_mm": 130,
                                      "planner": {"v0": 0.15}})
    pp = planner_params_001(p)
    assert pp.sonar.sensor_offset_m == pytest.approx(0.17)
    assert pp.sonar.shared_echo_tol_m == pytest.approx(0.13)
    assert pp.v0 == pytest.approx(0.15)  # the scenario's paper parameters still apply
    off = planner_params_001(TaskParams.for_method("001", {"sonar_shared_echo_mm": 0}))
    assert off.sonar.shared_echo_tol_m is None  # 0: eq. (15) as written


def test_every_field_builds_the_same_inputs_as_the_constructor():
    # the per-tick constructor of host.app_factory.InputBuilder skips the dataclass __init__:
    # it must set every field (a field added later and forgotten there fails here)
    from dataclasses import FrozenInstanceError, fields

    kw = {"joints_mrad": (0, 1, 2, 3, 4, 5), "x_mm": 7, "y_mm": -8, "heading_mrad": 9,
          "v_mmps": 10, "sonar_mm": (1, 2, 3, 4, 5), "detections": {"spoke": None},
          "grasp_closed": True}
    assert set(kw) == {f.name for f in fields(TaskInputs)}
    fast, slow = TaskInputs.every_field(**kw), TaskInputs(**kw)
    assert type(fast) is TaskInputs and vars(fast) == vars(slow) and fast == slow
    with pytest.raises(FrozenInstanceError):
        fast.x_mm = 1
