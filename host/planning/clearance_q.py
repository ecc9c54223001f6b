"""Clearance D_m of eq. (18) of 001 in fixed point: distance from path samples to the echo arcs.

An infeasible region of eq. (16) (host/planning/sonar_regions.py) stands for the echo arc at
range η across the sub-region's angles, seen from the sensing position O, grown by the safety
radius R_r. The clearance of a point P is its distance to that arc less R_r: |OP| − η when P
lies within the arc's angles (seen from O), else the distance to the nearer end of the arc.
D_m of a path is the least clearance over its samples and the regions.

Formats (those of host/planning/bezier_q.py): positions, η, R_r and the arc's end points in
1/16 mm (``_q4``); cos and sin of the bisector and tan of the half-angle in Q14. The angular
test is the cross-product form of eq. (16)'s θ_l <= θ_n <= θ_r (no arctangent): with
a = OP·(cos, sin) and b = |OP × (cos, sin)|, P is within the angles when a > 0 and
b <= a·tan(half-angle) (sub-regions are narrower than π). Each sample and region costs one
integer square root (of |OP|² inside the angles, of the nearer end's distance² outside).

Bounds: |coordinates| < 2^21 counts (bezier_q.COORD_LIMIT) give |OP| components < 2^22,
a, b < 2^37, b·2^14 < 2^51, a·tan < 2^57 (tan <= 2^20), squared distances < 2^45.
Against the float reference (tests/unit/host/test_planning_clearance.py): within 1 mm.
"""

from __future__ import annotations

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.planning.bezier_q import ISQRT64_OPS, TRIG_BITS, isqrt_array

CLEAR_WORDS = 11
NO_REGION_Q4 = (1 << 62)  # D_m when there is no region: larger than any distance
# per sample and region: offsets, the two projections, the angle test, |OP|² or the ends'
# distances², one root, the subtraction and the running minimum
CLEARANCE_OPS = ISQRT64_OPS + OpCounts(alu=30, muls32=3 * 8, branches=4)


def clearance_words(regions) -> np.ndarray:
    """Per region: O (ox, oy), cos and sin of the bisector and tan of the half-angle (Q14), η,
    R_r and the arc's end points (1/16 mm): host/planning/sonar_regions.py RegionWords, the
    region's set-up in integers, once a region."""
    out = [reg.words.clearance(reg) for reg in regions]
    return np.array(out, dtype=np.int64).reshape(-1, CLEAR_WORDS)


def point_clearance_q4(words: np.ndarray, x_q4, y_q4) -> np.ndarray:
    """Clearance (1/16 mm) of points (arrays broadcast) to each region: shape (R, *points)."""
    x = np.asarray(x_q4, dtype=np.int64)
    y = np.asarray(y_q4, dtype=np.int64)
    out = []
    for w in np.asarray(words, dtype=np.int64).reshape(-1, CLEAR_WORDS):
        ox, oy, c, s, tn, eta, r_r, e1x, e1y, e2x, e2y = (int(v) for v in w)
        rx, ry = x - ox, y - oy
        along = rx * c + ry * s
        across = np.abs(ry * c - rx * s)
        inside = (along > 0) & ((across << TRIG_BITS) <= along * tn)
        d_in = np.abs(isqrt_array(rx * rx + ry * ry) - eta)
        e1 = (x - e1x) ** 2 + (y - e1y) ** 2
        e2 = (x - e2x) ** 2 + (y - e2y) ** 2
        d_out = isqrt_array(np.minimum(e1, e2))
        out.append(np.where(inside, d_in, d_out) - r_r)
    return np.array(out, dtype=np.int64).reshape((-1,) + np.broadcast(x, y).shape)


def path_clearance_q4(words: np.ndarray, x_q4: np.ndarray, y_q4: np.ndarray) -> np.ndarray:
    """D_m (1/16 mm) of each path (rows of (N, n) samples): the least clearance over its
    samples and the regions; NO_REGION_Q4 without regions."""
    x = np.asarray(x_q4, dtype=np.int64)
    if len(words) == 0 or x.shape[-1] == 0:
        return np.full(x.shape[:-1], NO_REGION_Q4, dtype=np.int64)
    per = point_clearance_q4(words, x, y_q4)  # (R, N, n)
    return per.min(axis=(0, 2))


def clearance_ops(n_samples: int, n_regions: int) -> OpCounts:
    """ARM9 cost of D_m of one path."""
    return CLEARANCE_OPS.scaled(n_samples * n_regions)
