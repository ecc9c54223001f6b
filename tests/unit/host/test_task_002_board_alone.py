"""002 APPROACH: the board without its cylinder. Frames of the crosses at a range where the
cylinder before them would be in view too, none of them with red, end the run FAILED "no
graspable object found" instead of driving on into the board."""

from __future__ import annotations

import detections as det
import pytest

from mobigrasp.host.task import Task, TaskInputs
from mobigrasp.host.task.method002 import BOARD_ALONE_FRAMES, BOARD_ALONE_MM, _board_range_mm

FRAME_US = 66_667


def _approach() -> Task:
    """APPROACH on the double cross seen by the search, no object estimate."""
    task = Task("002")
    task.arm = [0, 0, -2100, -200, 2300, 0]
    task.ms.e_mrad, task.ms.e_dpx = 0, 40
    task.go(0, "APPROACH", "test: double cross seen")
    task.step(0, TaskInputs())
    return task


def _crosses(d_px: int, red: dict | None = None) -> dict:
    return {"double_cross": det.double_cross(160 * 16, 120 * 16, d_px * 16),
            "red_cylinder": None, "red_roi": None, **(red or {})}


def _run(task: Task, frames: list[dict]) -> list:
    """One frame a frame period; the outputs."""
    return [task.step(FRAME_US * (k + 1), TaskInputs(detections=f))
            for k, f in enumerate(frames)]


def test_the_board_alone_in_range_ends_failed_no_graspable_object():
    task = _approach()
    assert BOARD_ALONE_MM[0] <= _board_range_mm(task, 40) <= BOARD_ALONE_MM[1]
    outs = _run(task, [_crosses(40)] * BOARD_ALONE_FRAMES)
    assert [o.state for o in outs[:-1]] == ["APPROACH"] * (BOARD_ALONE_FRAMES - 1)
    assert outs[-1].state == "FAILED" and outs[-1].wheels_mmps == (0, 0)
    assert task.failure.startswith("no graspable object found: the double cross seen in "
                                   f"{BOARD_ALONE_FRAMES} frames")


def test_frames_without_a_frame_or_without_the_crosses_do_not_count():
    task = _approach()
    frames = []
    for _ in range(BOARD_ALONE_FRAMES - 1):
        frames += [_crosses(40), {}, {"double_cross": None, "red_cylinder": None,
                                      "red_roi": None}]
    outs = _run(task, frames)
    assert task.state == "APPROACH" and task.ms.alone_frames == BOARD_ALONE_FRAMES - 1
    assert all(o.state == "APPROACH" for o in outs)


@pytest.mark.parametrize("red", [
    {"red_roi": det.red_roi(150 * 16, 200 * 16)},
    {"red_cylinder": det.red_cylinder(150 * 16, 200 * 16, 5 * 16, 20 * 16)}])
def test_red_in_one_frame_of_the_approach_keeps_the_board(red):
    """The cylinder seen once (its ROI or its rings, far): the frames without it that follow
    are the detector missing it, not its absence."""
    task = _approach()
    _run(task, [_crosses(40, red)] + [_crosses(40)] * (2 * BOARD_ALONE_FRAMES))
    assert task.ms.alone_frames == 0 and task.state == "APPROACH"
    assert task.ms.red_seen or task.graspable_seen  # the rings: the object itself seen


@pytest.mark.parametrize("d_px", [15, 90])
def test_crosses_too_far_or_too_near_do_not_count(d_px):
    """Far, the ROI may be too small; near, the cylinder below the level look (the crosses'
    estimate then starts ADJUST)."""
    task = _approach()
    assert not BOARD_ALONE_MM[0] <= _board_range_mm(task, d_px) <= BOARD_ALONE_MM[1]
    _run(task, [_crosses(d_px)] * (2 * BOARD_ALONE_FRAMES))
    assert task.ms.alone_frames == 0 and task.state in ("APPROACH", "ADJUST")


def test_a_cylinder_whose_rings_were_measured_is_never_given_up_so():
    task = _approach()
    task.graspable_seen = True
    _run(task, [_crosses(40)] * (2 * BOARD_ALONE_FRAMES))
    assert task.state == "APPROACH"
