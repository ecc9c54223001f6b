"""001's grasp circle (eqs. (5)-(6)) is computed for the object's grasp point as built
(``grasp_height_mm``), not for 001 §IV's h_e = 0.208 m; the robot arrives on it and grasps
from there by eq. (11) of 000 when the look confirms the object (docs/task.md)."""

import pytest

from mobigrasp.host.planning.grasp_circle import grasp_radius
from mobigrasp.host.task import Task, TaskInputs
from mobigrasp.host.task.method001 import planner_params_001


def test_the_grasp_circle_is_for_the_grasp_height():
    p = Task("001").p
    arm = planner_params_001(p).arm
    assert arm.h_e == pytest.approx(p.grasp_height_mm / 1000.0)
    assert p.grasp_height_mm < 100  # below the object's top, 0.10 m
    # the arm reaches 0.08 m from further out than 0.208 m: a wider circle than 001 §IV's
    assert grasp_radius(arm).l_e_m == pytest.approx(0.306, abs=0.003)
    assert grasp_radius(arm).l_e_m > grasp_radius(type(arm)()).l_e_m + 0.04


def _on_the_circle(obj_off_mm: int = 0):
    """A 001 task whose path ended on the grasp circle of the object at (1500, 0) mm, the look
    before the grasp done; ``obj_off_mm``: where the look put the object, beside the estimate
    the base arrived with."""
    task = Task("001", {"object_xy_mm": [1500, 0], "sonar_sweep_us": 0})
    clear = (2500,) * 5
    task.step(0, TaskInputs(sonar_mm=clear))
    task.step(20_000, TaskInputs(sonar_mm=clear))
    assert task.state == "APPROACH" and task.ms.replanner is not None
    now = 1_000_000
    at = TaskInputs(x_mm=1500 - 310, sonar_mm=clear)  # the axle 310 mm from the object
    task.rules.path_end(task, now, at, "path followed", 3)
    assert task.state == "ROUGH_GRASP"
    circle = task._detail["grasp_circle"]
    assert circle["axle_mm"] == 310 and circle["error_mm"] == 310 - circle["l_e_mm"]
    assert circle["path_error_mm"] == 3 and circle["waist_mm"] == 210
    assert 280 <= circle["l_e_mm"] <= 330  # eqs. (5)-(6) for the 80 mm grasp height
    assert task.ms.circle_expected == (1500, 0)
    task.obj = (1500 + obj_off_mm, 0)
    return task, now, at


def test_001_grasps_by_eq_11_from_its_grasp_circle_when_the_look_confirms_the_object():
    from mobigrasp.host import kinematics

    task, now, at = _on_the_circle(obj_off_mm=20)
    task.sight_frames = 3
    assert task.rules.look_decides(task, now, at)
    assert task.state == "ROUGH_GRASP" and task.ms.ik_grasp and task.phase == ""
    x, y, z = kinematics.fk_mm_q4(task.geom, *task.arm[2:6])
    obj_x, obj_y = task.obj_platform(at)
    assert abs(x - obj_x) <= 2 * 16 and abs(y - obj_y) <= 2 * 16  # above the grasp point
    assert z > (task.p.object_top_mm - task.p.h_shoulder_mm) * 16  # over the top
    assert abs(task.grasp_alpha - kinematics.ALPHA_DOWN_MRAD) <= 30  # the gripper down
    task.go(now, "PRECISE_GRASP", "arm at the rough grasp pose")
    task.step(now + 20_000, at)  # down without the spoke's alignment
    assert task.phase == "lower" and task.close_by == "ik" and not task.ms.ik_grasp
    _, _, z = kinematics.fk_mm_q4(task.geom, *task.arm[2:6])
    assert abs(z - (task.p.grasp_height_mm - task.p.h_shoulder_mm) * 16) <= 2 * 16


def test_001_does_not_grasp_from_its_circle_on_a_look_that_did_not_confirm_the_object():
    # seen, but far from where the base expected it: 000's adjustment and precise grasp
    task, now, at = _on_the_circle(obj_off_mm=100)
    task.sight_frames = 3
    assert task.rules.look_decides(task, now, at)
    assert task.state == "ADJUST" and not task.ms.ik_grasp
    # not seen at all, the object seen by the camera before: never a grasp on absence
    task, now, at = _on_the_circle()
    task.sight_frames, task.object_sighted = 0, True
    assert task.rules.look_decides(task, now, at)
    assert task.state == "ADJUST" and not task.ms.ik_grasp
    # never seen by the camera: ADJUST too (its look then searches, grasp.py)
    task, now, at = _on_the_circle()
    task.sight_frames, task.object_sighted = 0, False
    assert task.rules.look_decides(task, now, at)
    assert task.state == "ADJUST" and not task.ms.ik_grasp
    assert task.ms.circle_expected is None  # the next look is not the circle's
    assert not task.rules.look_decides(task, now, at)


def test_001_started_on_its_grasp_circle_grasps_from_there():
    """No path needed (the base starts on the grasp circle): the look and the grasp from the
    circle as after a path, not 000's ADJUST."""
    task = Task("001", {"object_xy_mm": [300, 0], "sonar_sweep_us": 0})
    clear = (2500,) * 5
    for now in range(0, 200_000, 20_000):
        task.step(now, TaskInputs(sonar_mm=clear))
        if task.state != "APPROACH" and now:
            break
    assert task.state == "ROUGH_GRASP"
    assert task.ms.circle_expected == (300, 0)


def test_001_s_curve_ends_before_the_base_would_brake_onto_the_object():
    # the curve was planned for the object at (1500, 0); the estimate then moved 100 mm nearer,
    # less than replan_shift_mm: the curve's end lies inside the new estimate's grasp circle
    clear = (2500,) * 5
    task = Task("001", {"object_xy_mm": [1500, 0], "sonar_sweep_us": 0})
    task.step(0, TaskInputs(sonar_mm=clear))
    now = 20_000
    task.step(now, TaskInputs(sonar_mm=clear))
    while task.plan_job is not None:
        now += 20_000
        task.step(now, TaskInputs(sonar_mm=clear))
    assert task.state == "APPROACH" and task.follower is not None
    task.obj = (1400, 0)
    assert 1500 - 1400 < task.p.replan_shift_mm
    # the axle 300 mm from the estimate at 200 mm/s: ~30 mm of braking still leaves room
    task.step(now + 20_000, TaskInputs(x_mm=1100, v_mmps=200, sonar_mm=clear))
    assert task.state == "APPROACH"
    # 250 mm (the waist 150 mm from it, beyond ADJUST's goal): braked, the 170 mm footprint
    # would come within 60 mm of the estimate: the base stops here, on the grasp circle
    task.step(now + 40_000, TaskInputs(x_mm=1150, v_mmps=200, sonar_mm=clear))
    assert task.state == "ROUGH_GRASP"
    assert task._detail["grasp_circle"]["axle_mm"] == 250
    assert task._detail["grasp_circle"]["waist_mm"] > task.p.grasp_r_mm


def test_001_on_its_circle_facing_past_the_object_closes_in_before_the_grasp():
    """On the circle (axle 283 mm from the estimate) with the object behind and right of the
    base, out of the arm's reach and of every view of the look: ADJUST closes in on it first
    (at most MAX_SIGHT_ADJUSTS times a grasp, then FAILED), and the look after the close-in
    is not the circle's (000's grasp from there)."""
    from mobigrasp.host.task.grasp import MAX_SIGHT_ADJUSTS

    task = Task("001", {"object_xy_mm": [1500, 0], "sonar_sweep_us": 0})
    clear = (2500,) * 5
    task.step(0, TaskInputs(sonar_mm=clear))
    task.step(20_000, TaskInputs(sonar_mm=clear))
    now = 1_000_000
    past = TaskInputs(x_mm=1500 + 180, y_mm=218, heading_mrad=0, sonar_mm=clear)
    task.rules.path_end(task, now, past, "no path needed", None)
    assert task.state == "ROUGH_GRASP" and task._detail["grasp_circle"]["axle_mm"] == 282
    task.step(now + 20_000, past)
    assert task.state == "ADJUST" and task.sight_adjusts == 1
    why = task._events[-1].why
    assert why.startswith("rough grasp out of reach (out of reach: wrist point")
    assert why.endswith("): closer in first") and task.failure is None
    # closed in, the look then sees the object where the base expected it: not the circle's
    # grasp by eq. (11) (the base has moved since the arrival), 000's rough grasp from here
    task.sight_frames = 3
    assert not task.rules.look_decides(task, now, past) and task.ms.circle_expected is None
    # still out of reach after MAX_SIGHT_ADJUSTS close-ins: FAILED
    task.sight_adjusts = MAX_SIGHT_ADJUSTS
    task.go(now, "ROUGH_GRASP", "test")
    task.step(now + 40_000, past)
    assert task.state == "FAILED" and task.failure.startswith("rough grasp IK: out of reach")
