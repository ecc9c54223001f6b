"""002 APPROACH: with the double cross out of reach, the far red cylinder's column steers."""

from __future__ import annotations

from host.task import Task, TaskInputs

# a far red cylinder as the detector reports it (random 002 seed 3003, 2.8 m away)
FAR_CYLINDER = {"d_pixel_q4": 32, "ring1_v_q4": 912, "ring2_v_q4": 944, "roi": [158, 48, 12, 20],
                "v_c_q4": 928, "width_q4": 112}


def _approach(u_c_q4: int | None):
    task = Task("002")
    task.go(0, "APPROACH", "test: marker seen")
    rc = dict(FAR_CYLINDER, u_c_q4=u_c_q4) if u_c_q4 is not None else None
    out = None
    for k in range(1, 100):  # 2 s: past lost_timeout_us
        out = task.step(k * 20_000, TaskInputs(detections={"double_cross": None,
                                                             "red_cylinder": rc}))
    return task, out


def test_far_cylinder_on_the_right_turns_the_robot_right_and_drives():
    task, out = _approach(16 * 220)  # 60 px right of u0 = 160
    assert out.state == "APPROACH"
    left, right = out.wheels_mmps
    assert left > 0 and right > 0 and left > right  # forward, turning right (clockwise)
    assert task.arm[5] > 0  # the waist turns toward it (e right positive)


def test_far_cylinder_on_the_left_turns_left():
    _, out = _approach(16 * 100)
    left, right = out.wheels_mmps
    assert right > left


def test_without_the_cylinder_the_approach_is_lost():
    _, out = _approach(None)
    assert out.state in ("LOST", "SEARCH")
