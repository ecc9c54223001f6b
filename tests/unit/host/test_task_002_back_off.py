"""002 APPROACH: a red cylinder cut by the frame's border, its rings not measured, while the
estimate would start ADJUST at the grasp's reach: the base backs straight off and looks again."""

from __future__ import annotations

import detections as det
import pytest

from mobigrasp.host.task import Task, TaskInputs
from mobigrasp.host.task.method002 import BACK_OFF_002_MM, BACK_OFFS_002, _roi_cut

CUT_LEFT = (0, 60, 70, 180)  # the box touches the frame's left border
WHOLE = (120, 60, 60, 120)  # inside the 320 x 240 frame


def _task(estimate_mm: int) -> Task:
    """APPROACH with the object estimated ``estimate_mm`` ahead of the waist."""
    task = Task("002")
    task.arm = [0, 0, -2100, -200, 2300, 0]
    task.go(0, "APPROACH", "test: red ROI seen")
    task.step(0, TaskInputs())
    task.obj = (estimate_mm + task.p.mount_forward_mm, 0)  # the base at the origin, heading 0
    task.obj_seen_us = 0
    return task


def _frame(box) -> dict:
    return {"double_cross": None, "red_cylinder": None,
            "red_roi": det.red_roi(u_c_q4=16 * (box[0] + box[2] // 2),
                                   v_c_q4=16 * (box[1] + box[3] // 2), roi=box)}


@pytest.mark.parametrize(("box", "cut"), [
    (CUT_LEFT, True), (WHOLE, False), ((250, 10, 70, 50), True), ((100, 0, 30, 60), True),
    ((100, 150, 30, 90), True), ((1, 1, 318, 238), False)])
def test_a_box_touching_the_border_is_cut(box, cut):
    assert _roi_cut(Task("002"), det.red_roi(u_c_q4=0, v_c_q4=0, roi=box)) is cut
    assert _roi_cut(Task("002"), None) is False


def test_a_cut_cylinder_at_the_grasp_reach_backs_off_then_looks_again():
    task = _task(200)
    out = task.step(20_000, TaskInputs(detections=_frame(CUT_LEFT)))
    assert out.state == "APPROACH" and out.detail["back_off"] == {"dist_mm": 200, "n": 1}
    assert out.wheels_mmps == (-task.p.slow_mmps, -task.p.slow_mmps)
    # straight back on odometry, frames of the same cut cylinder meanwhile
    x, now = 0, 20_000
    while -x < BACK_OFF_002_MM:
        now += 20_000
        x -= task.p.slow_mmps * 20 // 1000
        out = task.step(now, TaskInputs(x_mm=x, detections=_frame(CUT_LEFT)))
        assert out.state == "APPROACH"
        assert out.wheels_mmps[0] < 0 or -x >= BACK_OFF_002_MM
    assert out.wheels_mmps == (0, 0)
    # a frame taken before the stop (within the frame latency) is not the look again
    out = task.step(now + 20_000, TaskInputs(x_mm=x, detections=_frame(CUT_LEFT)))
    assert out.wheels_mmps == (0, 0) and task.ms.back_off is not None
    # the look again: the cylinder whole, the estimate now 350 mm away: the approach goes on
    now += task.p.frame_latency_us + 20_000
    out = task.step(now, TaskInputs(x_mm=x, detections=_frame(WHOLE)))
    assert task.ms.back_off is None and not task.ms.cut and task.obj_seen_us == now
    assert out.state == "ADJUST"  # within grasp_r_mm + 150 and not cut: ADJUST


def test_a_whole_cylinder_or_one_far_enough_starts_adjust_without_backing_off():
    for estimate_mm, box in ((200, WHOLE), (380, CUT_LEFT)):
        task = _task(estimate_mm)
        out = task.step(20_000, TaskInputs(detections=_frame(box)))
        assert out.state == "ADJUST" and "back_off" not in out.detail


def test_a_cylinder_whose_rings_are_measured_is_not_cut():
    task = _task(200)
    rings = det.red_cylinder(u_c_q4=16 * 160, v_c_q4=16 * 120, d_pixel_q4=16 * 20,
                             width_q4=16 * 40)
    out = task.step(20_000, TaskInputs(detections={**_frame(CUT_LEFT), "red_cylinder": rings}))
    assert not task.ms.cut and "back_off" not in out.detail


def test_the_back_offs_of_a_run_are_bounded():
    task = _task(200)
    task.ms.back_offs = BACK_OFFS_002
    out = task.step(20_000, TaskInputs(detections=_frame(CUT_LEFT)))
    assert out.state == "ADJUST" and "back_off" not in out.detail


def test_an_estimate_the_grasp_never_sighted_does_not_decide_the_next_approach():
    """ADJUST finished on an estimate the rings never confirmed, red seen before: ROUGH_GRASP
    searches again and drops the estimate, so the next approach steers on the new sighting of
    the cut cylinder instead of backing off from, then closing in on, the old place."""
    task = _task(195)
    task.graspable_seen, task.ms.red_seen = False, True
    task.go(20_000, "ROUGH_GRASP", "test: ADJUST finished on the estimate")
    out = task.step(40_000, TaskInputs())
    assert out.state == "LOST" and task.obj is None
    # the search's sighting: the ROI at the left border, no range (cut)
    task.ms.e_mrad, task.ms.e_range_mm, task.ms.e_dpx = -344, None, None
    task.go(60_000, "APPROACH", "test: red ROI seen")
    cut = {"double_cross": None, "red_cylinder": None,  # left and bottom borders: no range
           "red_roi": det.red_roi(u_c_q4=552, v_c_q4=3576, roi=(0, 208, 70, 32),
                                  touches_edge=True)}
    out = task.step(80_000, TaskInputs(detections=cut))
    assert out.state == "APPROACH" and "back_off" not in out.detail
    assert out.detail["fuzzy"]["steer_on"] == "red_roi" and out.detail["fuzzy"]["e_mrad"] < 0
