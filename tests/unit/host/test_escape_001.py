"""001 near an obstacle: eq. (16) cut to the grown echo arc, the detour's way out, its drive."""

import math
from types import SimpleNamespace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mobigrasp.host.planning.escape import escape_heading, segment_clear
from mobigrasp.host.planning.sonar_regions import (
    InfeasibleRegion,
    SonarConfig,
    any_region_contains,
    infeasible_regions,
)
from mobigrasp.host.task import TaskInputs, TaskParams

# an echo 0.41 m from the centre in the narrow overlap of S_3 and S_4
NEAR = dict(ox=0.0, oy=0.0, lo_rad=0.26, hi_rad=0.525, eta_m=0.406, r_r_m=0.2)


def _arc_distance(reg: InfeasibleRegion, x: float, y: float) -> float:
    a = np.linspace(reg.lo_rad, reg.hi_rad, 2001)
    return float(np.min(np.hypot(x - reg.eta_m * np.cos(a), y - reg.eta_m * np.sin(a))))


def test_literal_wedge_covers_points_beside_the_robot_and_the_bound_frees_them():
    literal = InfeasibleRegion(**NEAR)
    bounded = InfeasibleRegion(**NEAR, arc_bound=True)
    # 0.25 m straight behind the robot, away from the echo: 0.65 m from the echo arc; and
    # 0.21 m from the centre, 75 degrees clockwise of the echo
    for d, off in ((0.25, math.pi), (0.21, -math.radians(75))):
        x, y = d * math.cos(0.3925 + off), d * math.sin(0.3925 + off)
        assert _arc_distance(literal, x, y) > 0.3
        assert literal.contains(x, y)  # eq. (16) as written: the strip through the robot
        assert not bounded.contains(x, y)
        assert not any_region_contains([bounded], x, y)
    # on the echo itself both agree
    assert literal.contains(0.35, 0.2) and bounded.contains(0.35, 0.2)


@settings(max_examples=150, deadline=None)
@given(st.floats(0.3, 2.4), st.floats(0.05, 0.6), st.floats(-3.1, 3.1), st.floats(0.0, 1.0),
       st.floats(-math.pi, math.pi), st.floats(0.0, 0.2))
def test_the_bound_never_frees_a_point_within_r_r_of_the_echo(eta, width, mid, along, dirn, r):
    reg = InfeasibleRegion(0.3, -0.2, mid - width / 2, mid + width / 2, eta, 0.2,
                           arc_bound=True)
    ang = reg.lo_rad + along * (reg.hi_rad - reg.lo_rad)
    x = reg.ox + eta * math.cos(ang) + 0.999 * r * math.cos(dirn)
    y = reg.oy + eta * math.sin(ang) + 0.999 * r * math.sin(dirn)
    literal = InfeasibleRegion(**{**reg.__dict__, "arc_bound": False})
    if literal.contains(x, y):  # the cut only removes points, never adds
        assert reg.contains(x, y)
        assert any_region_contains([reg], x, y)
    assert not (reg.contains(x, y) and not literal.contains(x, y))


def test_vectorised_test_matches_the_single_region_test_with_the_bound():
    cfg = SonarConfig(sensor_offset_m=0.17, shared_echo_tol_m=0.13, arc_angle_bound=True)
    scan = infeasible_regions(cfg, (0.1, 0.2), 0.4, [300, 700, 236, 225, 2600])
    assert scan.regions and all(r.arc_bound for r in scan.regions)
    rng = np.random.default_rng(7)
    x, y = rng.uniform(-1.5, 1.7, 4000), rng.uniform(-1.4, 1.8, 4000)
    ref = np.zeros(x.shape, dtype=bool)
    for reg in scan.regions:
        ref |= reg.contains(x, y)
    assert np.array_equal(any_region_contains(scan.regions, x, y), ref)


def test_escape_heading_is_the_clear_one_nearest_the_object():
    cfg = SonarConfig(sensor_offset_m=0.17, shared_echo_tol_m=0.13, arc_angle_bound=True)
    # facing +x, the object straight ahead, an echo front-left 0.23 m from the ring
    regions = infeasible_regions(cfg, (0.0, 0.0), 0.0, [65535, 65535, 225, 236, 65535]).regions
    head, ops = escape_heading(regions, (0.0, 0.0), 0.0, 0.0, 0.6, 0.1)
    assert head is not None and head < -0.2  # away from the echo, to the right
    assert segment_clear([_grown(r, 0.1) for r in regions], (0.0, 0.0), head, 0.6)[0]
    nearer = head + math.pi / 12  # the next heading toward the object is not clear
    assert not segment_clear([_grown(r, 0.1) for r in regions], (0.0, 0.0), nearer, 0.6)[0]
    assert ops.time_us() > 0
    assert segment_clear(regions, (0.0, 0.0), 0.0, 0.6)[0] is False
    # echoes close on every sonar: no way out within the ring's view
    walled = infeasible_regions(cfg, (0.0, 0.0), 0.0, [150] * 5).regions
    assert escape_heading(walled, (0.0, 0.0), 0.0, 0.0, 0.6)[0] is None


def _grown(reg: InfeasibleRegion, m: float) -> InfeasibleRegion:
    return InfeasibleRegion(**{**reg.__dict__, "r_r_m": reg.r_r_m + m})


def test_checked_detour_passes_beside_an_echo_and_stops_for_one_ahead():
    from mobigrasp.host.task.method001 import RULES, State001, detour_heading

    p = TaskParams.for_method("001")
    d = detour_heading(TaskInputs(sonar_mm=(65535,) * 5), (1500, 0), 900, heading_mrad=-900)
    assert d == {"heading_mrad": -900, "drive": True, "from": None, "checked": True}
    task = SimpleNamespace(p=p, wheels=None, ms=State001(detour=d))
    side = (65535, 65535, 65535, 220, 240)  # the obstacle beside it, front-left and left
    assert not RULES.detour_step(task, TaskInputs(heading_mrad=-900, sonar_mm=side))
    assert task.wheels == (p.wander_mmps, p.wander_mmps)
    # the unchecked detour stops for the same diagonal echo at once
    task.ms.detour = {"heading_mrad": -900, "drive": True, "from": None}
    assert RULES.detour_step(task, TaskInputs(heading_mrad=-900, sonar_mm=side))
    # something straight ahead stops a checked one too
    task.ms.detour = dict(d)
    assert RULES.detour_step(task, TaskInputs(heading_mrad=-900,
                                              sonar_mm=(65535, 65535, 300, 65535, 65535)))
    assert task.wheels == (0, 0)


def test_a_robot_already_too_close_may_leave_but_not_go_further_in():
    cfg = SonarConfig(sensor_offset_m=0.17, shared_echo_tol_m=0.13, arc_angle_bound=True)
    # an echo 0.1 m from the ring straight ahead: the robot stands inside its region grown by
    # the detour's 0.1 m margin
    regions = [_grown(r, 0.1) for r in infeasible_regions(
        cfg, (0.0, 0.0), 0.0, [65535, 65535, 100, 65535, 65535]).regions]
    assert any(r.contains(0.0, 0.0) for r in regions)
    assert segment_clear(regions, (0.0, 0.0), math.pi, 0.5, leave_ok=True)[0]  # straight back
    assert not segment_clear(regions, (0.0, 0.0), math.pi, 0.5)[0]
    assert not segment_clear(regions, (0.0, 0.0), 0.0, 0.5, leave_ok=True)[0]  # further in
    head, _ = escape_heading(regions, (0.0, 0.0), 0.0, 0.0, 0.6)
    assert head is not None and abs(head) >= 1.0  # sideways, away from the echo


def _on_the_circle(obj_off_mm: int = 0):
    """A 001 task whose path ended on the grasp circle of the object at (1500, 0) mm, the look
    before the grasp done; ``obj_off_mm``: where the look put the object, beside the estimate
    the base arrived with."""
    from mobigrasp.host.task import Task

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


def test_a_detour_keeps_to_the_side_of_the_first_one():
    cfg = SonarConfig(sensor_offset_m=0.17, shared_echo_tol_m=0.13, arc_angle_bound=True)
    # a wall-like echo straight ahead: both sides are open, the right one slightly nearer
    regions = infeasible_regions(cfg, (0.0, 0.0), 0.0, [65535, 65535, 250, 65535, 65535]).regions
    free, _ = escape_heading(regions, (0.0, 0.0), 0.0, -0.05, 0.6, 0.1)
    left, _ = escape_heading(regions, (0.0, 0.0), 0.0, -0.05, 0.6, 0.1, side=1)
    right, _ = escape_heading(regions, (0.0, 0.0), 0.0, -0.05, 0.6, 0.1, side=-1)
    assert free is not None and free < -0.05  # nearest the goal: right of it
    assert right == free
    assert left is not None and left > -0.05  # kept left although the right is nearer
    assert abs(left + 0.05) > abs(free + 0.05)


def test_001_started_on_its_grasp_circle_grasps_from_there():
    """No path needed (the base starts on the grasp circle): the look and the grasp from the
    circle as after a path, not 000's ADJUST."""
    from mobigrasp.host.task import Task

    task = Task("001", {"object_xy_mm": [300, 0], "sonar_sweep_us": 0})
    clear = (2500,) * 5
    for now in range(0, 200_000, 20_000):
        task.step(now, TaskInputs(sonar_mm=clear))
        if task.state != "APPROACH" and now:
            break
    assert task.state == "ROUGH_GRASP"
    assert task.ms.circle_expected == (300, 0)
