"""A toy detector for the registry test: the brightest pixel of the frame, as a typed result.

It is what a new detector module provides (docs/architecture.md, "Adding a detector"): the detector
function ``(rgb) -> (result | None, OpCounts)``, its frozen result dataclass, ``min_ops`` and
``sighting``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mobigrasp.host.budget import OpCounts

DEPTH_MM = 500  # the toy says every bright spot is this far along the optical axis


@dataclass(frozen=True)
class BrightSpot:
    """The brightest pixel (Q4 px) and its grey level."""

    u_q4: int
    v_q4: int
    level: int


def min_ops(height: int, width: int) -> OpCounts:
    """Every pixel is read once whatever the frame shows."""
    return OpCounts(pixels_read=height * width, alu=height * width)


def detect_bright_spot(rgb: np.ndarray) -> tuple[BrightSpot | None, OpCounts]:
    """The brightest pixel of the green channel, or None below level 200."""
    g = rgb[..., 1]
    ops = min_ops(*g.shape)
    i = int(np.argmax(g))
    v, u = divmod(i, g.shape[1])
    if int(g.flat[i]) < 200:
        return None, ops
    return BrightSpot(16 * u, 16 * v, int(g.flat[i])), ops


def sighting(res: BrightSpot, f_px: int) -> tuple[int, int, int] | None:
    """Pixel and depth (Q4 mm) of the spot: the task's target."""
    return res.u_q4, res.v_q4, DEPTH_MM * 16
