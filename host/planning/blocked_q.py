"""The path-update test of 001 §III.E in fixed point: does the rest of the present curve enter
an infeasible region (eq. (16))?

The curve's control points in 1/16 mm and 1/16 ms, τ in Q15 (host/planning/bezier_q.py's
formats). The present τ is where t(τ) (eq. (5) of 000, its time row) reaches the present time:
found by bisection over the Q15 grid, 15 halvings, t(τ) increasing on a feasible curve. The rest
[τ_now, 1] is sampled at m − 1 points after τ_now, τ_j = τ_now + (2^15 − τ_now)·j / (m − 1),
and each sample is tested against the regions as the planner does (bezier_q.in_regions_q).

Against the float reference (tests/unit/host/test_planning_replan_q.py): what is reported blocked is
blocked with R_r grown by 3 mm, what is reported clear is clear with R_r shrunk by 3 mm.
"""

from __future__ import annotations

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.planning.bezier_q import (
    POSITION_OPS,
    REGION_OPS_PER_SAMPLE,
    TAU_BITS,
    coefficients_q,
    horner_q,
    in_regions_q,
)

TAU_ONE = 1 << TAU_BITS
# one halving: t(τ) by Horner's rule (3 multiply-shift-adds), compare, move a bound
HALVING_OPS = OpCounts(alu=10, muls32=3 * 3, branches=2)


def tau_at_time_q15(ctrl_q: np.ndarray, t_q4: int) -> int:
    """The least τ (Q15) with t(τ) >= t_q4 (1/16 ms), 0 before the start, 2^15 after the end."""
    k = coefficients_q(np.asarray(ctrl_q, dtype=np.int64).reshape(1, 4, 3))[:, :, 2]
    lo, hi = 0, TAU_ONE
    while lo < hi:
        mid = (lo + hi) >> 1
        t, _, _ = horner_q(k, np.array([mid], dtype=np.int64))
        if int(t[0, 0]) < t_q4:
            lo = mid + 1
        else:
            hi = mid
    return lo


def first_blocked_q(ctrl_q: np.ndarray, tau0_q15: int, m: int, geo: np.ndarray, n_reg: int
                    ) -> tuple[tuple[int, int] | None, OpCounts]:
    """The first of the m − 1 samples after τ0 inside any region (x, y in 1/16 mm; None when
    clear) and the ARM9 cost of the test (each sample's position and region tests, the
    bisection)."""
    ctrl_q = np.asarray(ctrl_q, dtype=np.int64).reshape(1, 4, 3)
    j = np.arange(1, m, dtype=np.int64)
    tau = tau0_q15 + ((TAU_ONE - tau0_q15) * j) // (m - 1)
    k = coefficients_q(ctrl_q)
    x, _, _ = horner_q(k[:, :, 0], tau)
    y, _, _ = horner_q(k[:, :, 1], tau)
    hit = in_regions_q(geo, n_reg, x, y)[0]
    ops = (POSITION_OPS + REGION_OPS_PER_SAMPLE.scaled(n_reg)).scaled(m - 1) \
        + HALVING_OPS.scaled(TAU_BITS + 1)
    if not hit.any():
        return None, ops
    i = int(np.argmax(hit))
    return (int(x[0, i]), int(y[0, i])), ops
