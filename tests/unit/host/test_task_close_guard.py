"""The close guard (host/task/sonar_guard.py): ADJUST, driving forward, stops for a front echo
within CLOSE_GUARD_MM of the ring that is not the object's, or for a kept edge of an earlier
close echo's arc the footprint is about to reach, and grasps from there when the object is near
enough, else searches again (docs/task.md, "No contact")."""

import pytest

from mobigrasp.host.task import Task, TaskInputs
from mobigrasp.host.task.sonar_guard import (
    CLOSE_GUARD_MM,
    CLOSE_REACH_MM,
    CLOSE_SIDE_MM,
    close_echo,
)

CLEAR = (2500,) * 5


def _adjusting(obj_xy_mm: tuple[int, int]) -> Task:
    task = Task("002")
    task.obj, task.obj_seen_us = obj_xy_mm, 0
    task.go(0, "ADJUST", "test")
    return task


def test_adjust_drives_on_with_clear_sonars():
    task = _adjusting((420, 0))
    task.step(20_000, TaskInputs(sonar_mm=CLEAR))
    out = task.step(40_000, TaskInputs(sonar_mm=CLEAR))
    assert task.state == "ADJUST" and out.wheels_mmps[0] + out.wheels_mmps[1] > 0


@pytest.mark.parametrize("obj_x_mm, to", [(400, "ROUGH_GRASP"), (900, "LOST")])
def test_an_echo_in_front_of_the_object_stops_adjust(obj_x_mm, to):
    """002's board post 170 mm in front of the cylinder, 25 mm ahead of the ring: stop; the
    object 300 mm from the waist is graspable from there (grasp_r_mm + CLOSE_REACH_MM), one
    800 mm off is searched for again."""
    task = _adjusting((obj_x_mm, 0))
    task.step(20_000, TaskInputs(sonar_mm=CLEAR))
    post = (2500, 2500, CLOSE_GUARD_MM - 5, 2500, 2500)
    out = task.step(40_000, TaskInputs(sonar_mm=post))
    assert out.wheels_mmps == (0, 0) and task.state == to
    assert out.detail["close_guard"]["range_mm"] == CLOSE_GUARD_MM - 5
    assert (obj_x_mm - task.p.mount_forward_mm <= task.p.grasp_r_mm + CLOSE_REACH_MM) == (
        to == "ROUGH_GRASP")


def test_the_objects_own_echo_does_not_stop_it():
    """The object's near surface, a radius short of its centre estimate, is its own echo; the
    same range with the estimate 100 mm further is something in front of it."""
    task = Task("000")
    task.obj = (170 + 60, 0)  # centre 60 mm ahead of the front sonar
    assert close_echo(task, TaskInputs(sonar_mm=(2500, 2500, 20, 2500, 2500))) is None
    task.obj = (170 + 160, 0)
    assert close_echo(task, TaskInputs(sonar_mm=(2500, 2500, 20, 2500, 2500))) is not None
    # side sonars (phi = +-pi/2) see what the base passes, not what it drives into
    assert close_echo(task, TaskInputs(sonar_mm=(20, 2500, 2500, 2500, 20))) is None


def _post_read(task: Task) -> None:
    """ADJUST at the start, then a post read 45 mm from the front sonar (it stands at the cone's
    edge, 20-30 mm aside of the axis: the arc's edges 209 mm ahead of the axle, 22 mm aside)."""
    task.step(20_000, TaskInputs(sonar_mm=CLEAR))
    out = task.step(40_000, TaskInputs(sonar_mm=(2500, 2500, 45, 2500, 2500)))
    assert task.state == "ADJUST" and out.wheels_mmps[0] + out.wheels_mmps[1] > 0


def test_a_post_gone_from_the_cone_still_stops_adjust_before_the_footprint_reaches_it():
    """A thin post beside the front sonar's axis leaves its +-30 degree cone when ~45 mm away
    and no sonar sees it after, though the footprint (the ring's circle) is on its way: the
    edges of its echo's arc are kept on odometry, and the base stops once it would reach one
    within CLOSE_SIDE_MM of driving on (40 mm to go from the reading; the grasp goes on from
    there)."""
    task = _adjusting((420, 0))
    _post_read(task)
    out = task.step(60_000, TaskInputs(x_mm=6, sonar_mm=CLEAR))  # gone from the cone
    assert task.state == "ADJUST" and out.wheels_mmps[0] + out.wheels_mmps[1] > 0
    out = task.step(80_000, TaskInputs(x_mm=20, sonar_mm=CLEAR))
    assert task.state == "ADJUST" and out.wheels_mmps[0] + out.wheels_mmps[1] > 0
    out = task.step(100_000, TaskInputs(x_mm=30, sonar_mm=CLEAR))
    assert out.wheels_mmps == (0, 0) and task.state == "ROUGH_GRASP"
    guard = out.detail["close_guard"]
    assert guard["side"] == 1 and 0 <= guard["range_mm"] < CLOSE_SIDE_MM
    assert out.events[-1].why.startswith("close guard: a kept echo edge")


def test_a_kept_edge_seen_through_or_the_objects_own_echo_stops_nothing():
    """Backed off 60 mm, the front cone sees past where the post's arc was (nothing there): its
    edges are dropped and the base drives on past them; the object's own echo (its estimate in
    the cone, at most CLOSE_OBJECT_MM nearer than its centre) is not kept."""
    task = _adjusting((420, 0))
    _post_read(task)
    assert len(task.side_echoes) == 2
    task.step(60_000, TaskInputs(x_mm=-60, sonar_mm=CLEAR))
    assert task.side_echoes == []
    out = task.step(80_000, TaskInputs(x_mm=30, sonar_mm=CLEAR))
    assert task.state == "ADJUST" and out.wheels_mmps[0] + out.wheels_mmps[1] > 0
    task.step(100_000, TaskInputs(x_mm=30, sonar_mm=(2500, 2500, 200, 2500, 2500)))
    assert task.side_echoes == []


def test_the_drive_out_of_r_r_passes_beside_the_echo_that_stopped_the_base():
    """000 / 002: an echo below R_r at 45 degrees on the left, straight ahead free: the guard
    stops the base and drives out straight ahead, past that echo (only one straight ahead
    stops the drive out); with the diagonal threshold the base stood still, stopped again at
    every step (docs/task.md)."""
    task = Task("002")
    task.state, task.obj = "APPROACH", (3000, 1500)
    sonar = (150, 150, 2500, 196, 2500)  # the right side and S_4 (pi/4, left) near
    task.wheels = (150, 160)
    task.rules.guard_wheels(task, 0, TaskInputs(sonar_mm=sonar))
    assert task.wheels == (0, 0) and task.guard_out["heading_mrad"] == 0
    driven = []
    for k in range(1, 4):
        task.wheels = (150, 160)  # the state steering on toward the object
        task.rules.guard_wheels(task, k * 20_000, TaskInputs(y_mm=0, x_mm=10 * k,
                                                           sonar_mm=sonar))
        driven.append(task.wheels)
    assert driven == [(task.p.wander_mmps, task.p.wander_mmps)] * 3
    # an echo straight ahead within DETOUR_STOP_MM still ends the drive out
    task.rules.guard_wheels(task, 100_000, TaskInputs(x_mm=40, sonar_mm=(150, 150, 300, 196,
                                                                          2500)))
    assert task.wheels == (0, 0) and task.guard_out is None
