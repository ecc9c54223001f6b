"""The grasp circle of paper 001 (§III.B.1, eqs. (5)-(6)).

The 3-DOF arm model of eq. (5) of 001 (as printed, θ3 on the link l3 that leaves the base):

    h = l3 sin θ3 + l2 sin(θ2 + θ3) + l1 sin(θ1 + θ2 + θ3) + h_r
    l = l3 cos θ3 + l2 cos(θ2 + θ3) + l1 cos(θ1 + θ2 + θ3)

with θ1 ∈ [0, π], θ2, θ3 ∈ [−π/2, π/2]. Scanning all angle combinations at h = h_e gives
l_m = max l and l_n = min l, and the grasp-circle radius l_e = (l_m + l_n)/2. Instead of a 3-D
grid with a height tolerance we scan (θ2, θ3) on a grid and solve h = h_e for θ1 exactly
(sin(θ1 + θ2 + θ3) = (h_e − h_r − l3 sin θ3 − l2 sin(θ2 + θ3)) / l1, two roots, kept when
θ1 ∈ [0, π]); only reaches l >= 0 (in front of the base) count, since a grasp point behind the
base axis is not a place to drive to. End points (eq. (6)):
x_e^i = x_i + l_e cos φ_i, y_e^i = y_i + l_e sin φ_i, φ_i = 2π k_e / n_e, k_e = 1..n_e.

The scan is in integers (µm, µrad, Q14 sines: :func:`grasp_radius_um`, twin of hostc/grasp_circle.c
mg_grasp_radius_um), configuration-time work once per arm geometry, cached.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.fixedpoint import (
    ONE_Q12,
    atan2_urad,
    div_round,
    isqrt,
    sin_ops,
    sincos_turn_q12,
    sincos_urad_q14,
)


@dataclass(frozen=True)
class ArmGeometry001:
    """Arm of 001 §IV: link lengths and mounting height (m), grasp height h_e (m)."""

    l1: float = 0.16
    l2: float = 0.16
    l3: float = 0.2
    h_r: float = 0.108
    h_e: float = 0.208


@dataclass(frozen=True)
class GraspRadius:
    """Result of the scan: l_m, l_n and l_e = (l_m + l_n)/2 in metres."""

    l_max_m: float
    l_min_m: float

    @property
    def l_e_m(self) -> float:
        """Radius of the grasp circle."""
        return 0.5 * (self.l_max_m + self.l_min_m)


def arm_height_reach(arm: ArmGeometry001, th1, th2, th3) -> tuple[np.ndarray, np.ndarray]:
    """Eq. (5) of 001: (h, l) for joint angles (arrays broadcast)."""
    s3 = np.asarray(th3, dtype=np.float64)
    s23 = s3 + th2
    s123 = s23 + th1
    h = arm.l3 * np.sin(s3) + arm.l2 * np.sin(s23) + arm.l1 * np.sin(s123) + arm.h_r
    lr = arm.l3 * np.cos(s3) + arm.l2 * np.cos(s23) + arm.l1 * np.cos(s123)
    return h, lr


# (θ2, θ3) of eq. (5) scanned on [−π/2, π/2] in GRID_STEPS steps each (1°)
GRID_STEPS = 180
_HALF_PI_URAD = 1_570_796
_PI_URAD = 3_141_593
_TWO_PI_URAD = 6_283_185


@lru_cache(maxsize=16)
def grasp_radius_um(l1_um: int, l2_um: int, l3_um: int, h_r_um: int, h_e_um: int,
                    steps: int = GRID_STEPS) -> tuple[int, int] | None:
    """Eq. (5) of 001 in integers (hostc/grasp_circle.c mg_grasp_radius_um): (l_m, l_n) in µm,
    the largest and least reach l >= 0 at height h_e over (θ2, θ3) on a (steps + 1)² grid of
    µrad, θ1 solved from h = h_e (sin(θ1 + θ2 + θ3) in Q14, its two roots by atan2) and kept
    in [0, π]; None when no grid point reaches h_e."""
    d_um = h_e_um - h_r_um
    theta = [div_round((2 * i - steps) * _HALF_PI_URAD, steps) for i in range(steps + 1)]
    sc = {}

    def sincos(a: int) -> tuple[int, int]:
        if a not in sc:
            sc[a] = sincos_urad_q14(a)
        return sc[a]

    hi, lo = -1, -1
    for t2 in theta:
        for t3 in theta:
            s3, c3 = sincos(t3)
            s23, c23 = sincos(t2 + t3)
            num = (d_um << 14) - l3_um * s3 - l2_um * s23  # l1 sin(θ1 + θ2 + θ3), µm Q14
            if abs(num) > l1_um << 14:
                continue
            rest = div_round(num, l1_um)  # Q14
            base = atan2_urad(rest, isqrt((1 << 28) - rest * rest))
            for s123 in (base, _PI_URAD - base):
                t1 = s123 - t2 - t3
                t1 = t1 + _TWO_PI_URAD if t1 < 0 else t1
                t1 = t1 - _TWO_PI_URAD if t1 > _TWO_PI_URAD else t1
                if t1 > _PI_URAD:
                    continue
                reach = (l3_um * c3 + l2_um * c23 + l1_um * sincos(s123)[1]) >> 14
                if reach >= 0:
                    hi = max(hi, reach)
                    lo = reach if lo < 0 else min(lo, reach)
    return None if hi < 0 else (hi, lo)


def grasp_radius(arm: ArmGeometry001 = ArmGeometry001()) -> GraspRadius:
    """l_m and l_n of eq. (5) for the arm (its lengths and heights to the µm),
    :func:`grasp_radius_um`."""
    um = [round(v * 1e6) for v in (arm.l1, arm.l2, arm.l3, arm.h_r, arm.h_e)]
    r = grasp_radius_um(*um)
    if r is None:
        raise ValueError(f"grasp height h_e = {arm.h_e} m is out of reach of {arm}")
    return GraspRadius(r[0] / 1e6, r[1] / 1e6)


def end_points(object_xy_m, l_e_m: float, n_e: int = 36) -> np.ndarray:
    """Eq. (6) of 001: the n_e end points (n_e, 2) at φ = 2πk/n_e, k = 1..n_e."""
    if n_e < 1 or not l_e_m > 0:
        raise ValueError(f"need n_e >= 1 and l_e > 0, got n_e={n_e}, l_e={l_e_m}")
    phi = 2.0 * math.pi / n_e * np.arange(1, n_e + 1)
    ox, oy = (float(v) for v in object_xy_m)
    return np.stack([ox + l_e_m * np.cos(phi), oy + l_e_m * np.sin(phi)], axis=1)


def end_points_q(object_q4: tuple[int, int], l_e_q4: int, n_e: int = 36
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Eq. (6) in integers: the end points (n_e, 2) in 1/16 mm at φ_k = 2πk/n_e (k = 1..n_e,
    k/n_e of a turn: sincos_turn_q12, exact at the quarter turns, so an end point on an axis
    through the object stays on it), x_e = x_i + l_e cos φ_k (Q12, rounded), and the unit
    directions (n_e, 2) from each end point to the object, −(cos φ_k, sin φ_k) in Q14."""
    if n_e < 1 or l_e_q4 <= 0:
        raise ValueError(f"need n_e >= 1 and l_e > 0, got n_e={n_e}, l_e={l_e_q4}")
    ends = np.zeros((n_e, 2), dtype=np.int64)
    dirs = np.zeros((n_e, 2), dtype=np.int64)
    for i in range(n_e):
        s, c = sincos_turn_q12(i + 1, n_e)
        ends[i] = (object_q4[0] + div_round(l_e_q4 * c, ONE_Q12),
                   object_q4[1] + div_round(l_e_q4 * s, ONE_Q12))
        dirs[i] = (-(c << 2), -(s << 2))
    return ends, dirs


END_POINT_OPS_EACH = OpCounts(alu=12, muls32=3, divs=1, branches=1) + sin_ops().scaled(2) \
    + OpCounts(alu=10, muls32=2)  # k/n_e of a turn, cos and sin from the table, two products


def inside_circle(x: np.ndarray, y: np.ndarray, object_xy_m, radius_m: float,
                  margin_m: float = 1e-6) -> np.ndarray:
    """True where (x, y) is strictly inside the circle (less the margin): paths must not enter."""
    dx = x - float(object_xy_m[0])
    dy = y - float(object_xy_m[1])
    return dx * dx + dy * dy < (radius_m - margin_m) ** 2
