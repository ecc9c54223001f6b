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
Float (soft-float on the ARM9, ops counted like the planner's).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.planning.bezier import FLOPS_PER_REGION
from mobigrasp.host.planning.sonar_regions import InfeasibleRegion, any_region_contains

LEAVE_TOL_M = 0.02  # leaving a region: the arc may come this much closer on the way out


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


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
    px, py = (float(v) for v in position_xy_m)
    grown = [replace(r, r_r_m=r.r_r_m + margin_m) for r in regions] if margin_m else regions
    n_side = int(span_rad / step_rad + 1e-9)
    heads = [heading_rad + j * step_rad for j in range(-n_side, n_side + 1)]
    heads.sort(key=lambda h: (side * _wrap(h - goal_bearing_rad) < -1e-9,
                              abs(_wrap(h - goal_bearing_rad)), h))
    ops = OpCounts()
    for h in heads:
        clear, more = segment_clear(grown, (px, py), h, length_m, samples, leave_ok=True)
        ops = ops + more
        if clear:
            return _wrap(h), ops
    return None, ops


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
    px, py = (float(v) for v in position_xy_m)
    dist = length_m * np.arange(1, samples + 1) / samples
    xs, ys = px + dist * math.cos(heading_rad), py + dist * math.sin(heading_rad)
    ops = OpCounts(float_ops=samples * (4 + FLOPS_PER_REGION * len(regions)), luts=2)
    if not leave_ok:
        return not bool(any_region_contains(regions, xs, ys).any()), ops
    ops = ops + OpCounts(float_ops=(samples + 1) * 12 * len(regions), float_divs=2 * len(regions))
    for reg in regions:
        inside = reg.contains(xs, ys)
        if not inside.any():
            continue
        if not bool(reg.contains(px, py)):
            return False, ops
        if (inside & (reg.clearance(xs, ys) < float(reg.clearance(px, py)) - LEAVE_TOL_M)).any():
            return False, ops
    return True, ops
