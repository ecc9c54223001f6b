"""Cubic Bezier candidates with time checked in fixed point (000 eqs. (5)-(9), 001 (12)-(17)).

The integer form of host/planning/bezier.py's formulas that the planners decide with, and that
hostc/bezier.c computes operation for operation (the ARM920T has no FPU: a double add costs ~75
cycles there, an integer multiply 3-5). Formats (Q-format: the number of fraction bits):

- control points: x, y in 1/16 mm and t in 1/16 ms (``POS_PER_M`` = ``TIME_PER_S`` = 16000
  counts per metre and per second), so a ratio x_τ/t_τ is a speed in mm/ms = m/s;
- τ_j = (j << 15) / (n − 1), Q15; the derivatives of eq. (7) of 000 by Horner's rule with
  floor shifts (``>>`` on negative numbers is the arithmetic shift in numpy and in gcc);
- speed v = s / t_τ, m/s Q16; curvature |κ| = |x_τ y_2τ − x_2τ y_τ| / s³, 1/m Q16 (saturated
  at 2^31 − 1); 001's a = v²|κ| (eq. (14)) and 000's tangential a_t = (ṡ − v t_2τ) / t_τ² in
  m/s² Q16 (ṡ = (x_τ x_2τ + y_τ y_2τ) / s), s = ⌊√(x_τ² + y_τ²)⌋; quotients of signed numbers
  truncate toward zero, as C's ``/``;
- the speed test s·2^16 <= v_max·t_τ has no divide; t_τ > 0 on all of [0, 1] is exact
  (ends positive, and at the vertex 3c3·c1 > c2² when c3 > 0 and 0 < −c2 < 3c3);
- the grasp circle and eq. (16)'s regions in 1/16 mm with cos, sin and tan in Q14; the arc
  bound b >= |r| cos(bound) squared, b in 1/16 mm, cos² in Q16;
- eq. (9)/(17): the trapezoid sums of s (1/16 mm) and |κ| (Q16) over the samples, divided by
  2(n − 1); cost = k1·length + k2·∫|κ|dτ in Q16 (k1, k2 in Q16).

Range: every control point coordinate below 2^21 counts (131 m, 131 s) and v_max below 16 m/s
keep every product within 63 bits (the bounds are in the comments of :func:`evaluate_q`); a
curve outside gets the reason "range" at its first sample.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mobigrasp.host.budget import OpCounts

POS_PER_M = 16_000  # 1/16 mm
TIME_PER_S = 16_000  # 1/16 ms
TAU_BITS = 15
Q16 = 1 << 16
TRIG_BITS = 14
COORD_LIMIT = 1 << 21
KAPPA_SAT = (1 << 31) - 1
# |κ| Q16 = (|cross| << 6) / s · KAPPA_SCALE / s²: 16000 (1/m per 16/mm) · 2^16 / 2^6
KAPPA_SCALE = POS_PER_M * Q16 >> 6
# a Q16 = (m · 250 / t_τ) · 64 / t_τ: m/s² per (1/16 mm)/(1/16 ms)² is 16000 = 250 · 64
ACCEL_A, ACCEL_B = 250, 64

# reasons in the C's codes (hostc/bezier.h)
REASONS = ("ok", "time_not_increasing", "speed", "accel", "radius", "grasp_circle", "obstacle",
           "budget", "range")
CODE = {r: i for i, r in enumerate(REASONS)}
REGION_WORDS = 12
GEO_HEAD = 3


def quantize_ctrl(ctrl) -> np.ndarray:
    """Control points (..., 4, 3) in (m, m, s) to int64 counts of 1/16 mm and 1/16 ms."""
    a = np.asarray(ctrl, dtype=np.float64)
    return np.rint(a * POS_PER_M).astype(np.int64)


def limits_q(v_max: float, a_max: float, r_min: float | None, accel_is_normal: bool
             ) -> np.ndarray:
    """hostc/bezier.h ``lim``: v_max (m/s Q16), a_max (m/s² Q16), κ_max = 1/R_min (1/m Q16;
    −1: no radius test), accel_is_normal (1: 001's v²κ, 0: 000's |dv/dt|)."""
    kmax = -1 if r_min is None else round(Q16 / r_min)
    return np.array([round(v_max * Q16), round(a_max * Q16), kmax, int(accel_is_normal)],
                    dtype=np.int64)


def geo_q(obj_xy_m, radius_m: float, regions) -> np.ndarray:
    """hostc/bezier.h ``geo``: the grasp circle (centre, radius² in (1/16 mm)²), then per region
    of eq. (16) its words (host/planning/sonar_regions.py RegionWords.geo: its apex, cos and sin
    of its bisector and tan of its half-angle (Q14), the sensing position, the band's radii
    squared, the arc bound's flag, the sign of cos(bound) and cos²(bound) (Q16)), made in
    integers once per region."""
    q = POS_PER_M
    r = max(radius_m, 0.0) * q
    out = [round(obj_xy_m[0] * q), round(obj_xy_m[1] * q), math.floor(r * r)]
    for reg in regions:
        out += reg.words.geo(reg)
    return np.array(out, dtype=np.int64)


def isqrt_array(n: np.ndarray) -> np.ndarray:
    """Exact ⌊√n⌋ of non-negative int64 values below 2^62 (the C's mg_isqrt64)."""
    n = np.maximum(np.asarray(n, dtype=np.int64), 0)  # < 0 only where "range" overflowed
    r = np.floor(np.sqrt(n.astype(np.float64))).astype(np.int64)
    for _ in range(2):  # the float root is within one of the exact one
        r = np.where(r * r > n, r - 1, r)
        r = np.where((r + 1) * (r + 1) <= n, r + 1, r)
    return r


def _tdiv(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """C's a / b (truncation toward zero) for b > 0."""
    q = np.abs(a) // b
    return np.where(a < 0, -q, q)


def _min_t_positive(c1, c2, c3) -> np.ndarray:
    """t_τ = c1 + 2c2τ + 3c3τ² > 0 on all of [0, 1], exactly (candidates.min_t_tau's test)."""
    ends = (c1 > 0) & (c1 + 2 * c2 + 3 * c3 > 0)
    inner = (c3 > 0) & (-c2 > 0) & (-c2 < 3 * c3)
    return ends & (~inner | (3 * c3 * c1 > c2 * c2))


@dataclass(frozen=True)
class QBatch:
    """The fixed-point evaluation of a batch of curves at n samples."""

    reason: np.ndarray  # (N,) reason codes (REASONS)
    first: np.ndarray  # (N,) sample of the first violation, n when none
    length_q4: np.ndarray  # (N,) trapezoid ∫|P_τ|dτ, 1/16 mm (curves that passed)
    kint_q16: np.ndarray  # (N,) trapezoid ∫|κ|dτ, Q16 (curves that passed)
    x_q4: np.ndarray  # (N, n) positions, 1/16 mm (zeros without geometric tests)
    y_q4: np.ndarray

    @property
    def x(self) -> np.ndarray:
        """Sample positions in metres."""
        return self.x_q4 / POS_PER_M

    @property
    def y(self) -> np.ndarray:
        """Sample positions in metres."""
        return self.y_q4 / POS_PER_M

    def arc_length(self) -> np.ndarray:
        """Eq. (9)'s length term, metres."""
        return self.length_q4 / POS_PER_M

    def kappa_integral(self) -> np.ndarray:
        """Eq. (9)'s ∫|κ|dτ."""
        return self.kint_q16 / Q16

    def cost_q16(self, k1_q16: int, k2_q16: int) -> np.ndarray:
        """k1·length + k2·∫|κ|dτ, Q16 (the C's cost)."""
        return (k1_q16 * self.length_q4) // POS_PER_M + ((k2_q16 * self.kint_q16) >> 16)


def coefficients_q(ctrl_q: np.ndarray) -> np.ndarray:
    """Power-form coefficients (N, 4, 3) of quantized control points (N, 4, 3): eq. (6) of 000,
    k0 = P0, k1 = 3(P1 − P0), k2 = 3(P0 − 2P1 + P2), k3 = −P0 + 3P1 − 3P2 + P3."""
    p0, p1, p2, p3 = (ctrl_q[:, i, :] for i in range(4))
    return np.stack([p0, 3 * (p1 - p0), 3 * (p0 - 2 * p1 + p2), -p0 + 3 * p1 - 3 * p2 + p3],
                    axis=1)


def horner_q(k, tau):
    """Position, first and second derivative (eq. (6)-(7) of 000) of coefficients k (N, 4) at
    τ Q15 (n,): (N, n) each."""
    k0, k1, k2, k3 = (k[:, i, None] for i in range(4))
    t = tau[None, :]
    pos = k0 + ((t * (k1 + ((t * (k2 + ((t * k3) >> TAU_BITS))) >> TAU_BITS))) >> TAU_BITS)
    d1 = k1 + ((t * (2 * k2 + ((t * (3 * k3)) >> TAU_BITS))) >> TAU_BITS)
    d2 = 2 * k2 + ((t * (6 * k3)) >> TAU_BITS)
    return pos, d1, d2


def in_regions_q(geo: np.ndarray, n_reg: int, x, y) -> np.ndarray:
    """Eq. (16) in fixed point: True where a sample lies in any region (hostc/bezier.c
    in_region). Bounds: |x|, |q| < 2^21 -> along, across < 2^37, across·2^14 < 2^51,
    along·tan < 2^57, d2 < 2^45, d2·cos² < 2^61."""
    hit = np.zeros(x.shape, dtype=bool)
    for r in range(n_reg):
        w = geo[GEO_HEAD + REGION_WORDS * r: GEO_HEAD + REGION_WORDS * (r + 1)]
        qx, qy, c, s, tn, ox, oy, lo2, hi2, arc, cpos, cb2 = (int(v) for v in w)
        px, py = x - qx, y - qy
        along = px * c + py * s
        across = np.abs(py * c - px * s)
        rx, ry = x - ox, y - oy
        d2 = rx * rx + ry * ry
        inside = (along > 0) & ((across << TRIG_BITS) <= along * tn) & (d2 >= lo2) & (d2 <= hi2)
        if arc:
            b = (rx * c + ry * s) >> TRIG_BITS
            bb, lim = b * b, (d2 * cb2) >> 16
            inside &= ((b >= 0) & (bb >= lim)) if cpos else ((b >= 0) | (bb <= lim))
        hit |= inside
    return hit


def evaluate_q(ctrl_q: np.ndarray, n: int, lim: np.ndarray, geo: np.ndarray | None = None,
               n_reg: int = 0) -> QBatch:
    """Check a batch (N, 4, 3) of quantized curves at n samples, as hostc/bezier.c does each.

    Checking order per sample (the first failing one is the reason, at the first sample that
    fails any): range (sample 0), grasp circle, obstacle (not at sample 0: the robot is there),
    t_τ > 0 on [0, 1] (sample 0), t_τ > 0 and s > 0, speed, acceleration, turning radius (000).
    Bounds with |P| < 2^21: |k_i| < 2^24, |x_τ|, |x_2τ| < 2^27, s² < 2^55, |cross|, |dot| < 2^55,
    (|cross| << 6)/s < 2^34, its product with KAPPA_SCALE < 2^58, v < 2^20 (after the speed test),
    m < 2^48, m·250 < 2^56, the quotient's ·64 < 2^62.
    """
    ctrl_q = np.asarray(ctrl_q, dtype=np.int64).reshape(-1, 4, 3)
    m_cand, n = ctrl_q.shape[0], int(n)
    if n < 2:
        raise ValueError(f"n must be >= 2, got {n}")
    k = coefficients_q(ctrl_q)
    tau = (np.arange(n, dtype=np.int64) << TAU_BITS) // (n - 1)
    x, xt, x2 = horner_q(k[:, :, 0], tau)
    y, yt, y2 = horner_q(k[:, :, 1], tau)
    _, tt, t2 = horner_q(k[:, :, 2], tau)
    v_max, a_max, k_max, normal = (int(v) for v in lim)
    s = isqrt_array(xt * xt + yt * yt)
    ok_t = (tt > 0) & (s > 0)
    ts, ss = np.where(ok_t, tt, 1), np.where(ok_t, s, 1)
    speed_bad = ~ok_t | ((s << 16) > v_max * tt)
    cross = np.abs(xt * y2 - x2 * yt)
    q = (cross << 6) // ss
    kappa = np.minimum((q * KAPPA_SCALE) // (ss * ss), KAPPA_SAT)
    v = (s << 16) // ts
    checks: list[tuple[int, np.ndarray]] = []
    zero = np.zeros((m_cand, n), dtype=bool)
    rng = zero.copy()
    rng[:, 0] = np.any(np.abs(ctrl_q) >= COORD_LIMIT, axis=(1, 2))
    checks.append((CODE["range"], rng))
    if geo is not None:
        dx, dy = x - int(geo[0]), y - int(geo[1])
        checks.append((CODE["grasp_circle"], dx * dx + dy * dy < int(geo[2])))
        blocked = in_regions_q(geo, n_reg, x, y)
        blocked[:, 0] = False
        checks.append((CODE["obstacle"], blocked))
    t_all = zero.copy()
    t_all[:, 0] = ~_min_t_positive(k[:, 1, 2], k[:, 2, 2], k[:, 3, 2])
    checks.append((CODE["time_not_increasing"], t_all))
    checks.append((CODE["time_not_increasing"], ~ok_t))
    checks.append((CODE["speed"], speed_bad))
    if normal:
        acc = (((v * v) >> 16) * kappa) >> 16
    else:
        sdot = _tdiv(xt * x2 + yt * y2, ss)
        mm = (sdot << 16) - v * t2
        acc = np.abs(_tdiv(_tdiv(mm * ACCEL_A, ts) * ACCEL_B, ts))
    checks.append((CODE["accel"], acc > a_max))
    if not normal and k_max >= 0:
        checks.append((CODE["radius"], kappa > k_max))
    first = np.full(m_cand, n, dtype=np.int64)
    reason = np.zeros(m_cand, dtype=np.int64)
    for code, mask in checks:
        idx = np.where(mask.any(axis=1), mask.argmax(axis=1), n)
        earlier = idx < first
        first = np.where(earlier, idx, first)
        reason = np.where(earlier, code, reason)
    trap = 2 * (n - 1)
    length = (2 * s.sum(axis=1) - s[:, 0] - s[:, -1]) // trap
    kint = (2 * kappa.sum(axis=1) - kappa[:, 0] - kappa[:, -1]) // trap
    passed = reason == 0
    return QBatch(reason, first, np.where(passed, length, 0), np.where(passed, kint, 0),
                  x if geo is not None else np.zeros_like(x),
                  y if geo is not None else np.zeros_like(y))


# ARM920T cost of the C loop (hostc/bezier.c), per sample and per curve. A 64-bit product is
# one UMULL and two MLAs (``muls32``), a 64-bit quotient libgcc's __aeabi_ldivmod, a
# shift-subtract loop (ARMv4T has no CLZ; ``DIV64_OPS``, ~330 cycles on these operands); the
# root mg_isqrt64, one round per pair of bits of s² (~27 rounds of 64-bit compare, subtract and
# shifts in register pairs, ~22 cycles each). Calibrated against the C as ARM920T code
# (docs/budget.md): a 001 sample ~1960 cycles, a 000 sample ~2950 (the same in double
# soft-float: ~11 000); a curve ~430 cycles more, ~1090 more again when it passes.
DIV64_OPS = OpCounts(alu=270, branches=20)
ISQRT64_OPS = OpCounts(alu=27 * 16, branches=27 * 2)
SAMPLE_BASE_OPS = OpCounts(alu=120, muls32=3 * 12, divs=1, branches=4)  # τ, x_τ..t_2τ, s², tests
POSITION_OPS = OpCounts(alu=20, muls32=3 * 6)  # x, y by Horner's rule
CIRCLE_OPS = OpCounts(alu=8, muls32=3 * 2, branches=1)
REGION_OPS_PER_SAMPLE = OpCounts(alu=16, muls32=3 * 3, branches=2)  # most exit after `along`
CURVE_SETUP_OPS = OpCounts(alu=250, muls32=3 * 10, branches=10)  # the call, coefficients, t_τ
PASS_OPS = DIV64_OPS.scaled(3) + OpCounts(alu=100)  # a curve that passes: integrals and cost


def sample_ops(n_samples: int, *, positions: bool = False, grasp_circle: bool = False,
               regions: int = 0, divs_per_sample: int = 6) -> OpCounts:
    """ARM9 cost of evaluating one curve at ``n_samples`` points (plus its set-up).

    ``divs_per_sample``: 64-bit quotients per sample, 3 for 001 (κ twice, v), 6 for 000 (and
    ṡ, the two of a_t)."""
    per = SAMPLE_BASE_OPS + ISQRT64_OPS + DIV64_OPS.scaled(divs_per_sample)
    if positions or grasp_circle or regions:
        per = per + POSITION_OPS
    if grasp_circle:
        per = per + CIRCLE_OPS
    per = per + REGION_OPS_PER_SAMPLE.scaled(regions)
    return per.scaled(n_samples) + CURVE_SETUP_OPS
