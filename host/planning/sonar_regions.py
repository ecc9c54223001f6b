"""Sonar sub-regions and infeasible regions of paper 001 (§III.C.2, eqs. (15)-(16)), in integers.

k_s sonars; sensor S_k (k = 1..k_s) looks along φ_s^k = −π/2 + (k−1)π/(k_s−1) relative to the
direction of motion. Angles here are counter-clockwise positive (world convention), so S_1 looks
to the right and S_{k_s} to the left; ``sonar_mm[k-1]`` is the range of S_k. Each cone is A_g wide
and sees up to D_e; ρ_s^k = D_e when nothing is detected.

Sub-regions: if A_g <= π/(k_s−1) the regions R_v (v = 1..k_s) are the cones and η_R^v = ρ_s^k;
otherwise adjacent cones overlap and there are 2k_s − 1 sub-regions: v = 2k−1 the part seen by
S_k alone (η = ρ_s^k) and v = 2k the overlap of S_k and S_{k+1} (η = max(ρ_s^k, ρ_s^{k+1}),
eq. (15)). A region with η < D_e holds an obstacle; its infeasible region (eq. (16)) is the set of
points P_n with θ_l^v <= θ_n <= θ_r^v and η − R_r <= D_n <= η + R_r, where θ_n is the direction
from Q_r to P_n, Q_r is the intersection of the region's two boundary lines moved outward by the
safety radius R_r (it lies on the bisector, R_r / sin(half-angle) behind the sensing position),
and D_n is the distance from the sensing position to P_n.

Formats (host/planning/bezier_q.py's): positions, ranges and radii in 1/16 mm (``_q4``), angles
in micro-radians (``_urad``), sine, cosine and tangent in Q14 (host/fixedpoint.py
``sincos_urad_q14``, the sine table through a binary angle). A region is its integers
(:class:`InfeasibleRegion`); the words the tests use (:class:`RegionWords`: the apex, the
bisector's cos and sin, tan of the half-angle, the band's radii squared, the arc bound, the echo
arc's ends and middle) are made from them once (:func:`region_words`), with no float, as
hostc/sonar_regions.c makes them. The float geometry is the tests' reference
(tests/region_ref.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import lru_cache

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.fixedpoint import isqrt, isqrt_ops, sin_ops, sincos_urad_q14
from mobigrasp.host.planning.bezier_q import DIV64_OPS, POS_PER_M, TRIG_BITS

PI_URAD = 3_141_593
TAN_MAX_Q14 = 1 << 20  # tan of a half-angle near π/2, saturated (the tests' bounds hold)
ONE_Q14 = 1 << TRIG_BITS
# one region's words: sine and cosine of four angles, the apex's, the tangent's and the
# bound's quotients, the bound's root, the products and roundings
REGION_SETUP_OPS = sin_ops().scaled(8) + DIV64_OPS.scaled(3) + isqrt_ops(1 << 32) \
    + OpCounts(alu=40, muls32=3 * 10, branches=6)


@dataclass(frozen=True)
class SonarConfig:
    """Sonar ring of 001 §IV (configuration: SI floats, turned into integers once,
    :func:`sonar_q`)."""

    k_s: int = 5
    a_g_rad: float = 1.05
    d_e_m: float = 2.5
    r_r_m: float = 0.2  # safety circle radius R_r
    # Not in 001 (None = eq. (15) as written): when two neighbouring sonars report the same echo
    # within this tolerance, it is taken to come from their overlap only, and the sub-regions that
    # only one of them sees are left free.
    shared_echo_tol_m: float | None = None
    # Not in 001 (0 = as written): sonars mounted this far from the centre along their axes
    # measure from there; η is then taken from the centre (ρ + offset), as D_n of eq. (16) is.
    sensor_offset_m: float = 0.0
    # Not in 001 (False = eq. (16) as written): also bound the region by the exact angular
    # extent of the echo arc grown by R_r, seen from the sensing position (InfeasibleRegion).
    arc_angle_bound: bool = False

    def __post_init__(self) -> None:
        if self.k_s < 2 or not 0 < self.a_g_rad < math.pi or not self.d_e_m > 0:
            raise ValueError(f"SonarConfig needs k_s >= 2, 0 < A_g < π, D_e > 0: {self}")


@dataclass(frozen=True)
class SonarQ:
    """A SonarConfig in integers (hostc/sonar_regions.h ``mg_sonar_cfg_t``)."""

    k_s: int
    a_g_urad: int
    d_e_q4: int
    r_r_q4: int
    tol_q4: int  # < 0: no shared-echo rule
    offset_q4: int
    arc_bound: bool
    cot_half_q12: int  # cot(A_g / 2) in Q12 (the ring's span, replan.py forget_seen)

    def axis_urad(self, k: int) -> int:
        """φ_s^k relative to the direction of motion, k = 1..k_s (rounded)."""
        return _div_round((2 * (k - 1) - (self.k_s - 1)) * PI_URAD, 2 * (self.k_s - 1))


@lru_cache(maxsize=64)
def sonar_q(cfg: SonarConfig) -> SonarQ:
    """The configuration's integers (configuration time, once per SonarConfig)."""
    tol = cfg.shared_echo_tol_m
    return SonarQ(cfg.k_s, round(cfg.a_g_rad * 1e6), round(cfg.d_e_m * POS_PER_M),
                  round(cfg.r_r_m * POS_PER_M), -1 if tol is None else round(tol * POS_PER_M),
                  round(cfg.sensor_offset_m * POS_PER_M), bool(cfg.arc_angle_bound),
                  cot_half_q12(round(cfg.a_g_rad * 1e6)))


def cot_half_q12(a_g_urad: int) -> int:
    """cot(A_g / 2) in Q12 from the Q14 sine table (hostc/config.c's twin)."""
    s, c = sincos_urad_q14((a_g_urad + 1) // 2)
    return (2 * c * 4096 + s) // (2 * s)


def _div_round(num: int, den: int) -> int:
    """num / den rounded, halves away from zero (hostc mg_div_round64), den > 0."""
    q = (abs(num) * 2 + den) // (2 * den)
    return q if num >= 0 else -q


@dataclass(frozen=True)
class SubRegion:
    """Angular sub-region R_v relative to the heading: [lo, hi] (µrad, CCW) and its η."""

    v: int
    lo_urad: int
    hi_urad: int
    eta_q4: int


def sub_regions(cfg: SonarConfig, rho_q4) -> list[SubRegion]:
    """Eq. (15) of 001: the sub-regions and η_R^v for ranges ρ_s^k (1/16 mm, k = 1..k_s)."""
    c = sonar_q(cfg)
    if len(rho_q4) != c.k_s:
        raise ValueError(f"expected {c.k_s} sonar ranges, got {len(rho_q4)}")
    rho = [min(int(r) + c.offset_q4, c.d_e_q4) if int(r) < c.d_e_q4 else c.d_e_q4
           for r in rho_q4]
    half = c.a_g_urad >> 1
    axes = [c.axis_urad(k) for k in range(1, c.k_s + 1)]
    lo = [a - half for a in axes]
    hi = [a + half for a in axes]
    # A_g <= π/(k_s − 1): the cones do not overlap
    if c.a_g_urad * (c.k_s - 1) <= PI_URAD:
        return [SubRegion(k + 1, lo[k], hi[k], rho[k]) for k in range(c.k_s)]
    out = []

    def shared(a: int, b: int) -> bool:
        return (c.tol_q4 >= 0 and 0 <= b < c.k_s and rho[a] < c.d_e_q4
                and abs(rho[a] - rho[b]) <= c.tol_q4)

    for k in range(c.k_s):  # k is 0-based here: sensor S_{k+1}
        start = hi[k - 1] if k > 0 else lo[k]
        end = lo[k + 1] if k + 1 < c.k_s else hi[k]
        alone = c.d_e_q4 if shared(k, k - 1) or shared(k, k + 1) else rho[k]
        out.append(SubRegion(2 * k + 1, start, end, alone))
        if k + 1 < c.k_s:
            out.append(SubRegion(2 * k + 2, lo[k + 1], hi[k], max(rho[k], rho[k + 1])))
    return out


@dataclass(frozen=True)
class InfeasibleRegion:
    """Eq. (16) of 001 in the world frame: the sector seen from the sensing position.

    ``arc_bound`` (ours, SonarConfig.arc_angle_bound): eq. (16)'s wedge stands for the echo arc
    grown by the safety circle R_r, but for the narrow sub-regions of eq. (15) its apex Q_r lies
    0.8-1.5 m behind the sensing position, so its band η ± R_r also covers a strip R_r wide
    beside and behind the robot (points 0.2 m from it, away from the echo). Every point within
    R_r of the arc is seen from the sensing position within asin(R_r / η) of the arc's angles;
    the bound keeps only those, so it never frees a point that is within R_r of the echo."""

    ox_q4: int  # sensing position, 1/16 mm
    oy_q4: int
    lo_urad: int  # world direction of the clockwise boundary line
    hi_urad: int  # world direction of the counter-clockwise boundary line
    eta_q4: int
    r_r_q4: int
    arc_bound: bool = False

    def grown(self, by_q4: int) -> InfeasibleRegion:
        """The same region with R_r grown by ``by_q4``."""
        return replace(self, r_r_q4=self.r_r_q4 + int(by_q4)) if by_q4 else self

    @property
    def words(self) -> RegionWords:
        """Its fixed-point words (made once per region)."""
        return region_words(self)


@dataclass(frozen=True)
class RegionWords:
    """A region's words (hostc/sonar_regions.h ``mg_region_words_t``): 1/16 mm, Q14, Q16."""

    qx: int  # apex Q_r
    qy: int
    cos_mid: int  # bisector, Q14
    sin_mid: int
    tan_half: int  # tan of the half-angle, Q14 (−1: an empty wedge, half-angle <= 0)
    lo2: int  # max(η − R_r, 0)²
    hi2: int  # (η + R_r)²
    arc: int  # 1: the arc bound applies (arc_bound and η > R_r)
    cb_pos: int  # 1 when cos(bound) >= 0
    cb2_q16: int  # cos²(bound), Q16
    e1x: int  # the echo arc's ends (at lo, hi) and middle, 1/16 mm
    e1y: int
    e2x: int
    e2y: int
    mx: int
    my: int

    def geo(self, reg: InfeasibleRegion) -> list[int]:
        """hostc/bezier.h ``geo``'s words of the region."""
        return [self.qx, self.qy, self.cos_mid, self.sin_mid, self.tan_half, reg.ox_q4,
                reg.oy_q4, self.lo2, self.hi2, self.arc, self.cb_pos, self.cb2_q16]

    def clearance(self, reg: InfeasibleRegion) -> list[int]:
        """clearance_q.py's words of the region."""
        return [reg.ox_q4, reg.oy_q4, self.cos_mid, self.sin_mid, self.tan_half, reg.eta_q4,
                reg.r_r_q4, self.e1x, self.e1y, self.e2x, self.e2y]


def _rot(r_q4: int, c_q14: int) -> int:
    return _div_round(r_q4 * c_q14, ONE_Q14)


@lru_cache(maxsize=1024)
def region_words(reg: InfeasibleRegion) -> RegionWords:
    """Eq. (16)'s words of a region in integers (hostc/sonar_regions.c mg_region_words).

    mid = ⌊(lo + hi) / 2⌋, half = ⌊(hi − lo) / 2⌋ (µrad); Q_r = O − (R_r / sin half)·(cos, sin)
    mid; the bound's cosine cos(half + asin(R_r / η)) = (cos half·√(η² − R_r²) − sin half·R_r)
    / η, no arcsine. Bounds: |O| < 2^21, η, R_r < 2^20 counts: every product within 2^56."""
    mid = (reg.lo_urad + reg.hi_urad) >> 1
    half = (reg.hi_urad - reg.lo_urad) >> 1
    s_m, c_m = sincos_urad_q14(mid)
    s_h, c_h = sincos_urad_q14(half)
    eta, r_r = reg.eta_q4, reg.r_r_q4
    if half <= 0 or s_h <= 0:
        tan_half, back = -1, 0
    else:
        tan_half = min(_div_round(s_h << TRIG_BITS, c_h), TAN_MAX_Q14) if c_h > 0 \
            else TAN_MAX_Q14
        back = _div_round(r_r << TRIG_BITS, s_h)
    arc = int(reg.arc_bound and eta > r_r)
    cb_pos, cb2 = 0, 1 << 16
    if arc:
        cb = _div_round(c_h * isqrt(eta * eta - r_r * r_r) - s_h * r_r, eta)  # Q14
        cb_pos, cb2 = int(cb >= 0), (cb * cb + (1 << 11)) >> 12
    s_lo, c_lo = sincos_urad_q14(reg.lo_urad)
    s_hi, c_hi = sincos_urad_q14(reg.hi_urad)
    ox, oy = reg.ox_q4, reg.oy_q4
    return RegionWords(ox - _rot(back, c_m), oy - _rot(back, s_m), c_m, s_m, tan_half,
                       max(eta - r_r, 0) ** 2, (eta + r_r) ** 2, arc, cb_pos, cb2,
                       ox + _rot(eta, c_lo), oy + _rot(eta, s_lo), ox + _rot(eta, c_hi),
                       oy + _rot(eta, s_hi), ox + _rot(eta, c_m), oy + _rot(eta, s_m))


@dataclass(frozen=True)
class SonarScan:
    """Result of turning one sonar reading into infeasible regions."""

    regions: list[InfeasibleRegion]
    dropped: int  # readings that were not valid numbers >= 0 and were treated as "no echo"


def reading_q4(r) -> int | None:
    """One range (mm) in 1/16 mm; None when it is not a number >= 0 (bad input)."""
    if isinstance(r, int) and not isinstance(r, bool):
        return r * 16 if r >= 0 else None
    try:
        val = float(r)
    except (TypeError, ValueError):
        return None
    return round(val * 16) if math.isfinite(val) and val >= 0 else None


def infeasible_regions_q(cfg: SonarConfig, px_q4: int, py_q4: int, heading_urad: int,
                         sonar_mm) -> SonarScan:
    """Infeasible regions (world frame) of one sonar reading taken at a pose (1/16 mm, µrad).

    ``sonar_mm[k-1]`` is the range of S_k in millimetres (telemetry); values of D_e or more mean
    no echo. Readings that are negative or not numbers are counted in ``dropped`` and ignored.
    """
    c = sonar_q(cfg)
    if len(sonar_mm) != c.k_s:
        raise ValueError(f"expected {c.k_s} sonar ranges (mm), got {len(sonar_mm)}")
    rho, dropped = [], 0
    for r in sonar_mm:
        val = reading_q4(r)
        if val is None:
            dropped += 1
            val = c.d_e_q4
        rho.append(val)
    h = int(heading_urad)
    regions = [InfeasibleRegion(int(px_q4), int(py_q4), h + sr.lo_urad, h + sr.hi_urad,
                                sr.eta_q4, c.r_r_q4, c.arc_bound)
               for sr in sub_regions(cfg, rho) if sr.eta_q4 < c.d_e_q4]
    return SonarScan(regions, dropped)


def infeasible_regions(cfg: SonarConfig, position_xy_m, heading_rad: float,
                       sonar_mm) -> SonarScan:
    """:func:`infeasible_regions_q` at a pose in metres and radians (the planners' SI
    arguments, which the task makes from whole mm and mrad: rounded back to the same counts)."""
    return infeasible_regions_q(cfg, round(float(position_xy_m[0]) * POS_PER_M),
                                round(float(position_xy_m[1]) * POS_PER_M),
                                round(float(heading_rad) * 1e6), sonar_mm)
