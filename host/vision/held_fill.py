"""A frame filled by one colour: the object the gripper holds, seen by the camera in the hand.

The eye-in-hand camera's optical centre is the fingertip point (eq. (3) of 000), so an object
held between the fingers is all the camera sees: the frame is that object's surface, whatever
the arm does (docs/task.md, "Positive grasp evidence"). An object standing on the ground fills
no frame once the fingertip has left it. The detector samples every ``STEP``-th pixel of every
``STEP``-th row, takes the per-channel median and counts the samples within ``TOL`` of it in
all three channels; ``FILL_MIN_PERMILLE`` of them or more is a filled frame, reported with its
colour. The floor seen from above fills a frame too (its texture is low in contrast), so the
method decides whether the colour is its object's (``OBJECT_COLOURS``, by the object's kind:
the 000/001 object's brown body, the 002 cylinder's red paint, docs/markers.md).
Integer arithmetic only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.vision.red_cylinder import red_mask

STEP = 4  # sample grid: 80 x 60 of a 320 x 240 frame
TOL = 48  # a sample within this of the median in every channel (noise std up to 12, x4)
FILL_MIN_PERMILLE = 900


@dataclass(frozen=True)
class HeldFill:
    """The frame's median colour and the share of samples near it (per mille)."""

    rgb: tuple[int, int, int]
    fill_permille: int


def _check(rgb: np.ndarray) -> None:
    if not (isinstance(rgb, np.ndarray) and rgb.dtype == np.uint8 and rgb.ndim == 3
            and rgb.shape[2] == 3 and rgb.shape[0] >= STEP and rgb.shape[1] >= STEP):
        raise ValueError("detect_held_fill: expected an (H, W, 3) uint8 RGB frame, got "
                         f"{getattr(rgb, 'dtype', type(rgb).__name__)} "
                         f"{getattr(rgb, 'shape', '')}")


def detect_held_fill(rgb: np.ndarray) -> tuple[HeldFill | None, OpCounts]:
    """The colour that fills the frame, or ``(None, ops)`` when no colour fills it."""
    _check(rgb)
    grid = rgb[::STEP, ::STEP].reshape(-1, 3)
    n = grid.shape[0]
    ops = min_ops(rgb.shape[0], rgb.shape[1])
    # the lower median of each channel (a 256-bin histogram walk on the target)
    med = np.sort(grid, axis=0)[(n - 1) // 2].astype(np.int16)
    near = (np.abs(grid.astype(np.int16) - med) <= TOL).all(axis=1)
    fill = int(np.count_nonzero(near)) * 1000 // n
    if fill < FILL_MIN_PERMILLE:
        return None, ops
    return HeldFill((int(med[0]), int(med[1]), int(med[2])), fill), ops


def min_ops(height: int, width: int) -> OpCounts:
    """What :func:`detect_held_fill` charges on any frame: three histograms of the samples
    and their walks, then three differences, compares and a count per sample."""
    h, w = int(height), int(width)
    n = ((h + STEP - 1) // STEP) * ((w + STEP - 1) // STEP)
    return OpCounts(pixels_read=2 * 3 * n, alu=3 * n + 3 * 256 + 8 * n, branches=n + 3 * 256,
                    divs=1, bytes_streamed=(h + STEP - 1) // STEP * w * 3)


def body_brown(rgb: tuple[int, int, int]) -> bool:
    """The 000/001 object's body (170, 130, 90 under any brightness): R > G > B with R at
    least 1.5 B; the floor (~150, 142, 128) is at most 1.3."""
    r, g, b = rgb
    return r >= 40 and r > g > b and 2 * r >= 3 * b


def red_paint(rgb: tuple[int, int, int]) -> bool:
    """The 002 cylinder's red: the red mask's rule (host/vision/red_cylinder.py)."""
    return bool(red_mask(np.array([[rgb]], np.uint8))[0, 0])


OBJECT_COLOURS = {"body_brown": body_brown, "red_paint": red_paint}
