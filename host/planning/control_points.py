"""The candidates' control points in integers: 000 §III.B.1 and eqs. (7)-(11) of 001.

From the start P0 = q_s with unit start direction d̂_0 to an end P3 = q_e with unit end
direction d̂_3, for u = 1..N_i:

    t3 = |q_s P_i| / v0                                            (7)
    N_i = ⌊t3 / T_s⌋ (at least 1)
    P1 = (x_s + uΔd_s d̂_0x, y_s + uΔd_s d̂_0y, uΔd_s / v0)           (8)
    P2 = (x_e − uΔd_e d̂_3x, y_e − uΔd_e d̂_3y, t3 − uΔd_e / v3)      (9)
    Δd_e = |q_s P_i| / N_i (10),  Δd_s = Δd_e / 4 (11),  v3 = v0.

000 has one end (the stand-off point, |P0P3| for |q_s P_i|); 001 one per grasp-circle end point
with the same |q_s P_i|. Formats are the curve evaluation's (:mod:`bezier_q`): positions in
1/16 mm, times in 1/16 ms; unit directions in Q14; v0 in mm/s, T_s in ms. The per-plan
quantities are rounded once (t3, Δd_e, Δd_s and their times uΔd/v0 per unit u); a candidate then
costs products and shifts only. hostc/control_points.c computes the same integers.
"""

from __future__ import annotations

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.fixedpoint import cos_q12, div_round, isqrt, isqrt_ops, sin_q12
from mobigrasp.host.planning.bezier_q import DIV64_OPS

DIR_BITS = 14  # unit directions in Q14
ONE_DIR = 1 << DIR_BITS
MM_PER_Q4_TIME = 1000  # (1/16 mm) / (mm/s) = 1/16 s = 1000 · (1/16 ms)

# t3, N_i, Δd_e, Δd_s and the two times per unit u: six 64-bit quotients, and the call
PLAN_NUMBERS_OPS = DIV64_OPS.scaled(6) + OpCounts(alu=40, muls32=6, branches=4)
# a unit vector: its length (a root of up to 44 bits) and two rounded quotients
UNIT_OPS = isqrt_ops(1 << 44) + DIV64_OPS.scaled(2) + OpCounts(alu=16, muls32=6, branches=2)
# one candidate's control points: u times four per-plan steps, four 64-bit products with a
# direction, the rounding shifts and twelve stores
CANDIDATE_OPS = OpCounts(alu=40, muls32=4 * 3 + 4, branches=1)


def unit_q14(dx: int, dy: int) -> tuple[int, int] | None:
    """(dx, dy) / |(dx, dy)| in Q14, rounded; None for the zero vector."""
    n = isqrt(dx * dx + dy * dy)
    if n == 0:
        return None
    return div_round(dx << DIR_BITS, n), div_round(dy << DIR_BITS, n)


def heading_q14(heading_mrad: int) -> tuple[int, int]:
    """(cos, sin) of a heading in Q14 (the Q12 table's values, shifted)."""
    return cos_q12(heading_mrad) << 2, sin_q12(heading_mrad) << 2


def start_direction_q(vel_q4: tuple[int, int], heading_mrad: int | None,
                      fallback_q14: tuple[int, int], moving_q4: int) -> tuple[int, int]:
    """Unit start direction (Q14): the velocity (1/16 mm per s) when its speed is at least
    ``moving_q4``, else the heading, else the fallback."""
    vx, vy = int(vel_q4[0]), int(vel_q4[1])
    if vx * vx + vy * vy >= moving_q4 * moving_q4:
        d = unit_q14(vx, vy)
        if d is not None:
            return d
    if heading_mrad is not None:
        return heading_q14(heading_mrad)
    return fallback_q14


def plan_numbers(dist_q4: int, v0_mm_s: int, t_s_ms: int) -> tuple[int, int, int, int, int,
                                                                     int]:
    """(t3, N_i, Δd_e, Δd_s, Δt_e, Δt_s): eq. (7), N_i = ⌊t3 / T_s⌋ >= 1, eqs. (10)-(11), and
    the times Δd / v0 of one step u (1/16 mm, 1/16 ms)."""
    if dist_q4 < 0 or v0_mm_s <= 0 or t_s_ms <= 0:
        raise ValueError(f"plan_numbers: need dist >= 0, v0 > 0, T_s > 0, got {dist_q4}, "
                         f"{v0_mm_s}, {t_s_ms}")
    t3 = div_round(dist_q4 * MM_PER_Q4_TIME, v0_mm_s)  # eq. (7)
    n_i = max(1, t3 // (t_s_ms * 16))
    dd_e = div_round(dist_q4, n_i)  # eq. (10)
    dd_s = div_round(dist_q4, 4 * n_i)  # eq. (11): Δd_e / 4, rounded once
    dt_e = div_round(dist_q4 * MM_PER_Q4_TIME, n_i * v0_mm_s)  # Δd_e / v0
    dt_s = div_round(dist_q4 * MM_PER_Q4_TIME, 4 * n_i * v0_mm_s)  # Δd_s / v0
    return t3, n_i, dd_e, dd_s, dt_e, dt_s


def _step(u: np.ndarray, d: np.ndarray, direction: int) -> np.ndarray:
    """u·Δd·d̂ (Q14) rounded to 1/16 mm, halves away from zero as the C's shift does."""
    p = u * d * direction
    return np.where(p >= 0, (p + (ONE_DIR >> 1)) >> DIR_BITS,
                    -((-p + (ONE_DIR >> 1)) >> DIR_BITS))


def control_points_q(p0_q4: tuple[int, int], d0_q14: tuple[int, int], ends_q4: np.ndarray,
                     d3_q14: np.ndarray, numbers: tuple[int, ...]) -> np.ndarray:
    """Eqs. (8)-(9): the (M·N_i, 4, 3) int64 control points, end point by end point, u = 1..N_i
    within each (``numbers`` from :func:`plan_numbers`; ``ends_q4`` and ``d3_q14`` (M, 2))."""
    t3, n_i, dd_e, dd_s, dt_e, dt_s = (int(v) for v in numbers)
    ends = np.asarray(ends_q4, dtype=np.int64).reshape(-1, 2)
    d3 = np.asarray(d3_q14, dtype=np.int64).reshape(-1, 2)
    n_end = ends.shape[0]
    u = np.tile(np.arange(1, n_i + 1, dtype=np.int64), n_end)
    k = np.repeat(np.arange(n_end), n_i)
    ctrl = np.zeros((u.size, 4, 3), dtype=np.int64)
    ctrl[:, 0, 0], ctrl[:, 0, 1] = p0_q4
    ctrl[:, 1, 0] = p0_q4[0] + _step(u, dd_s, d0_q14[0])
    ctrl[:, 1, 1] = p0_q4[1] + _step(u, dd_s, d0_q14[1])
    ctrl[:, 1, 2] = u * dt_s
    ctrl[:, 2, 0] = ends[k, 0] - _step(u, dd_e, d3[k, 0])
    ctrl[:, 2, 1] = ends[k, 1] - _step(u, dd_e, d3[k, 1])
    ctrl[:, 2, 2] = t3 - u * dt_e  # v3 = v0
    ctrl[:, 3, :2] = ends[k]
    ctrl[:, 3, 2] = t3
    return ctrl


def control_points_ops(n_candidates: int) -> OpCounts:
    """ARM9 cost of the per-plan numbers and ``n_candidates`` control point sets."""
    return PLAN_NUMBERS_OPS + CANDIDATE_OPS.scaled(n_candidates)
