"""001's look before the grasp (host/task/grasp.py, docs/task.md): with the base standing still
the camera looks back at the object's top, and the grasp goes on that sighting; an object the
camera never saw is searched for, never grasped blind."""

import math

import test_task_closed_loop as loop

from mobigrasp.host.task import Task

ARM_001 = (160.0, 160.0, 200.0)


def test_the_grasp_goes_on_the_look_not_on_the_estimate_adjust_ended_with(monkeypatch):
    """The object slides 25 mm aside once ADJUST has ended (the estimate is then 25 mm off, as
    after a blind finish on odometry): the look sees it there and the first grasp holds it."""
    monkeypatch.setattr(loop, "H_SHOULDER_M", 0.108)
    task = Task("001")
    world = loop.World((1.4, 0.2), lengths=ARM_001)
    moved = []

    def slide(task, world):
        if task.state == "ROUGH_GRASP" and not moved:
            # 25 mm to the left of the line from the base to the object
            h = math.atan2(world.obj[1] - world.y, world.obj[0] - world.x)
            world.obj = (world.obj[0] - 0.025 * math.sin(h), world.obj[1] + 0.025 * math.cos(h))
            moved.append(task.obj)

    details = []
    events = loop.run(task, world, on_step=slide, details=details)
    assert moved, [e.to_state for e in events]
    assert task.state == "DONE" and world.held, (task.failure, [e.why for e in events])
    assert task.regrasps == 0, [e.why for e in events]  # the first grasp held it
    sights = [d["sight"] for d in details if "sight" in d]
    assert sights and sights[0]["frames"] > 0, sights
    # the estimate the grasp went on moved by the slide, from the one ADJUST ended with
    shift = math.hypot(task.obj[0] - moved[0][0], task.obj[1] - moved[0][1])
    assert 15 <= shift <= 35, (task.obj, moved[0])


def test_an_object_never_seen_is_searched_for_not_grasped_blind(monkeypatch):
    """P_i given, the object elsewhere (the camera never sees it): at the grasp the look finds
    nothing, and the task searches (LOST) instead of closing the gripper where P_i lies."""
    monkeypatch.setattr(loop, "H_SHOULDER_M", 0.108)
    task = Task("001", {"object_xy_mm": [1400, 200]})
    world = loop.World((6.0, -6.0), lengths=ARM_001)
    closes = []

    def watch(task, world):
        if task.gripper == 1000:
            closes.append(task.state)

    details = []
    events = loop.run(task, world, t_end_us=60_000_000, on_step=watch, details=details)
    path = [e.to_state for e in events]
    assert "ROUGH_GRASP" in path and "LOST" in path, path
    # the look from the grasp circle sees nothing: ADJUST (whose look searches), never a close
    between = path[path.index("ROUGH_GRASP") + 1:path.index("LOST")]
    assert set(between) <= {"ADJUST", "ROUGH_GRASP"}, path
    assert "never seen by the camera" in events[path.index("LOST")].why
    assert "PRECISE_GRASP" not in path and not closes, path
    sights = [d["sight"] for d in details if "sight" in d]
    assert sights and sights[0]["frames"] == 0, sights
