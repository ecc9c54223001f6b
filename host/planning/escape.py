"""A straight way out through free sonar space, clear of 001's infeasible regions (eq. (16)).

Used by the task's detour (host/task/method001.py) when no candidate curve of eq. (17) is
feasible from where the robot stands: typically an obstacle a few decimetres ahead, whose
infeasible region (the echo arc grown by the safety radius R_r, eq. (16)) covers every
direction a curve can leave in while keeping a_t = v²κ <= A_max (eq. (14)) at the start.
The base can turn in place, so it turns to a heading whose straight segment of ``length_m``
enters none of the regions and drives it; planning again from there, the obstacle is off the
way.  Ours, not 001's (001 always finds a curve in its simulations); the test is 001's own
eq. (16), with the regions optionally grown by ``margin_m`` because the drive is open-loop.

Headings are tried every ``step_rad`` within ``span_rad`` of the present heading (the ring's
S_1..S_k_s only see ±π/2 about it, so nothing further round is known to be free), nearest the
object's bearing first.  Where the robot already stands in a region (closer to an echo than
R_r and the margin) a heading leading away from that echo, its distance growing, is clear.
In integers: headings in mrad (Q12 sine and cosine, host/fixedpoint.py), the segment's samples
in 1/16 mm, eq. (16) as the planner tests it (bezier_q.in_regions_q) and the distance to the
echo arc as D_m (clearance_q). Against the float reference (tests/unit/host/test_escape_q.py):
a segment found clear is clear with R_r shrunk by 3 mm, one found blocked is blocked with R_r
grown by 3 mm.
"""

from __future__ import annotations

import math

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.fixedpoint import mrad_from_rad, sincos_q12
from mobigrasp.host.planning.bezier_q import (
    POS_PER_M,
    POSITION_OPS,
    REGION_OPS_PER_SAMPLE,
    geo_q,
    in_regions_q,
)
from mobigrasp.host.planning.clearance_q import (
    CLEARANCE_OPS,
    clearance_words,
    point_clearance_q4,
)
from mobigrasp.host.planning.sonar_regions import REGION_SETUP_OPS, InfeasibleRegion

LEAVE_TOL_M = 0.02  # leaving a region: the arc may come this much closer on the way out
TURN_URAD = 6_283_185
# a region's fixed-point words (sonar_regions.region_words, in integers): its set-up
REGION_WORDS_OPS = REGION_SETUP_OPS


def _wrap_urad(a: int) -> int:
    return (a + TURN_URAD // 2) % TURN_URAD - TURN_URAD // 2


def escape_heading(regions: list[InfeasibleRegion], position_xy_m, heading_rad: float,
                   goal_bearing_rad: float, length_m: float, margin_m: float = 0.0,
                   step_rad: float = math.pi / 12, span_rad: float = math.pi / 2,
                   samples: int = 16, side: int = 0) -> tuple[float | None, OpCounts]:
    """The heading (rad, world) nearest ``goal_bearing_rad`` whose straight segment from
    ``position_xy_m`` of ``length_m`` stays out of every region; None when there is none.
    ``side`` +1 (-1): headings left (right) of the goal bearing, or on it, come first: a
    detour that went round one side keeps to it (as a bug algorithm keeps its turning
    direction) rather than swinging back and forth between two blocked ways.

    Returns (heading or None, ARM9 ops of the test)."""
    if not length_m > 0 or samples < 1 or not step_rad > 0:
        raise ValueError(f"escape_heading: length_m > 0, samples >= 1, step_rad > 0 needed, "
                         f"got {length_m}, {samples}, {step_rad}")
    margin_q4 = round(margin_m * POS_PER_M)
    grown = [r.grown(margin_q4) for r in regions]
    h_urad, step_urad = round(heading_rad * 1e6), round(step_rad * 1e6)
    goal_urad = round(goal_bearing_rad * 1e6)
    n_side = int(span_rad / step_rad + 1e-9)  # the call's configuration
    heads = [h_urad + j * step_urad for j in range(-n_side, n_side + 1)]
    heads.sort(key=lambda h: (side * _wrap_urad(h - goal_urad) < 0,
                              abs(_wrap_urad(h - goal_urad)), h))
    words = _Words(grown)
    ops = REGION_WORDS_OPS.scaled(len(grown))
    for h in heads:
        clear, more = _segment_clear(words, position_xy_m, h // 1000, length_m, samples,
                                     leave_ok=True)
        ops = ops + more
        if clear:
            return _wrap_urad(h) / 1e6, ops
    return None, ops


class _Words:
    """The regions' fixed-point words, made once for all the segments tested against them."""

    def __init__(self, regions: list[InfeasibleRegion]) -> None:
        self.n = len(regions)
        self.all = geo_q((0.0, 0.0), 0.0, regions)
        self.each = [(geo_q((0.0, 0.0), 0.0, [r]), clearance_words([r])) for r in regions]


def segment_clear(regions: list[InfeasibleRegion], position_xy_m, heading_rad: float,
                  length_m: float, samples: int = 16,
                  leave_ok: bool = False) -> tuple[bool, OpCounts]:
    """True when the straight segment of ``length_m`` along ``heading_rad`` enters none of the
    regions (eq. (16) at ``samples`` points after the start); with the ARM9 ops of the test.

    ``leave_ok``: a region the start itself lies in (the robot already closer to an echo than
    R_r plus the margin) may be crossed where the segment is farther from that echo's arc
    than the start less LEAVE_TOL_M (D_m of eq. (18) not shrinking): the way out of it, not
    further in; sideways past the end of a short arc comes LEAVE_TOL_M closer at most."""
    if length_m <= 0:
        return True, OpCounts()
    clear, ops = _segment_clear(_Words(regions), position_xy_m, mrad_from_rad(heading_rad),
                                length_m, samples, leave_ok)
    return clear, ops + REGION_WORDS_OPS.scaled(len(regions))


def _segment_clear(words: _Words, position_xy_m, heading_mrad: int, length_m: float,
                   samples: int, leave_ok: bool) -> tuple[bool, OpCounts]:
    px = round(float(position_xy_m[0]) * POS_PER_M)
    py = round(float(position_xy_m[1]) * POS_PER_M)
    s, c = sincos_q12(heading_mrad)
    dist = round(length_m * POS_PER_M) * np.arange(1, samples + 1, dtype=np.int64) // samples
    xs, ys = px + ((dist * c) >> 12), py + ((dist * s) >> 12)
    ops = (POSITION_OPS + REGION_OPS_PER_SAMPLE.scaled(words.n)).scaled(samples) \
        + OpCounts(luts=2)
    if not leave_ok:
        return not bool(in_regions_q(words.all, words.n, xs, ys).any()), ops
    ops = ops + CLEARANCE_OPS.scaled((samples + 1) * words.n)
    start = np.array([px], dtype=np.int64), np.array([py], dtype=np.int64)
    tol_q4 = round(LEAVE_TOL_M * POS_PER_M)
    for geo, clear_words in words.each:
        inside = in_regions_q(geo, 1, xs, ys)
        if not inside.any():
            continue
        if not bool(in_regions_q(geo, 1, *start)[0]):
            return False, ops
        d_start = int(point_clearance_q4(clear_words, *start)[0, 0])
        if (inside & (point_clearance_q4(clear_words, xs, ys)[0] < d_start - tol_q4)).any():
            return False, ops
    return True, ops
