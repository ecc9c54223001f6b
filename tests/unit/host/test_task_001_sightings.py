"""001 APPROACH: sightings taken while the base turns fast do not move the object estimate; the
follower never backs up; the sonar guard stops the base and leaves the safety circle."""

import math

import detections as det

from mobigrasp.host.task import Task, TaskInputs

RADIAL_AHEAD = det.radial(160 * 16, 150 * 16, 1000)
CLEAR = (2500,) * 5


def _approaching(turn_mrad_per_step: int) -> Task:
    task = Task("001", {"object_xy_mm": [1500, 0], "sonar_sweep_us": 0})
    task.step(0, TaskInputs(sonar_mm=CLEAR))
    task.step(20_000, TaskInputs(sonar_mm=CLEAR))
    assert task.state == "APPROACH" and task.follower is not None
    h = 0
    for k in range(2, 10):  # 20 ms steps, turning at turn_mrad_per_step / 20 ms
        h += turn_mrad_per_step
        task.step(k * 20_000, TaskInputs(heading_mrad=h, v_mmps=100, sonar_mm=CLEAR))
    task.step(10 * 20_000, TaskInputs(heading_mrad=h + turn_mrad_per_step, v_mmps=100,
                                      sonar_mm=CLEAR, detections={"radial_symbol": RADIAL_AHEAD}))
    return task


def test_a_sighting_while_turning_fast_keeps_the_estimate():
    task = _approaching(30)  # 1.5 rad/s, as in a tight low-speed 001 curve
    assert task.obj == (1500, 0)


def test_a_sighting_while_turning_slowly_updates_the_estimate():
    task = _approaching(4)  # 0.2 rad/s
    assert task.obj != (1500, 0)


def test_001_never_backs_up_while_following_it_turns_on_the_spot():
    from types import SimpleNamespace

    task = Task("001", {"object_xy_mm": [1500, 0], "sonar_sweep_us": 0,
                        "replan_period_us": 10_000_000})
    task.step(0, TaskInputs(sonar_mm=CLEAR))
    task.step(20_000, TaskInputs(sonar_mm=CLEAR))
    assert task.state == "APPROACH"
    wheels = {"cmd": (-100, -20)}  # a reference fallen behind: back up, turning left

    class Stand:  # a follower stand-in commanding the wheels above
        def step(self, now, pose):
            return SimpleNamespace(left_mm_s=wheels["cmd"][0], right_mm_s=wheels["cmd"][1],
                                   done=False, error_mm=0)

    task.follower = Stand()
    out = task.step(40_000, TaskInputs(sonar_mm=CLEAR))
    assert out.wheels_mmps == (-40, 40)  # the turn kept, no travel backward
    wheels["cmd"] = (120, 80)
    out = task.step(60_000, TaskInputs(sonar_mm=CLEAR))
    assert out.wheels_mmps == (120, 80)  # forward commands unchanged


def test_the_sonar_guard_stops_turns_and_leaves_the_safety_circle_before_planning():
    """A front sonar below R_r in APPROACH: the base stops at once, turns toward the widest free
    sector and drives GUARD_OUT_MM along it before a new plan (docs/task.md, "No contact")."""
    from mobigrasp.host.task.sonar_guard import GUARD_OUT_MM

    task = Task("001", {"object_xy_mm": [1500, 0], "sonar_sweep_us": 0})
    task.step(0, TaskInputs(sonar_mm=CLEAR))
    task.step(20_000, TaskInputs(sonar_mm=CLEAR))
    assert task.state == "APPROACH" and task.follower is not None
    near = (2500, 2500, 150, 2500, 2500)  # straight ahead, inside R_r = 200 mm
    out = task.step(40_000, TaskInputs(v_mmps=100, sonar_mm=near))
    assert out.wheels_mmps == (0, 0) and task.follower is None
    assert out.detail["sonar_guard"]["range_mm"] == 150
    goal = task.ms.detour["heading_mrad"]
    assert task.ms.detour["drive"] and task.ms.detour["length_mm"] == GUARD_OUT_MM
    # turned toward the free sector (a side sonar), then driven straight along it
    out = task.step(60_000, TaskInputs(sonar_mm=near))
    assert out.wheels_mmps[0] == -out.wheels_mmps[1] != 0  # turning in place
    t, x, y = 80_000, 0, 0
    driven = []
    while task.ms.detour is not None and t < 20_000_000:
        out = task.step(t, TaskInputs(x_mm=x, y_mm=y, heading_mrad=goal, sonar_mm=CLEAR))
        if out.wheels_mmps[0] > 0 and out.wheels_mmps[0] == out.wheels_mmps[1]:
            driven.append((x, y))
            x += round(out.wheels_mmps[0] * 0.02 * math.cos(goal / 1000))
            y += round(out.wheels_mmps[0] * 0.02 * math.sin(goal / 1000))
        t += 20_000
    assert driven and math.hypot(x, y) >= GUARD_OUT_MM, (x, y)
    assert task.state == "APPROACH"
