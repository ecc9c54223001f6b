"""Sonar sub-regions and infeasible regions of paper 001 (§III.C.2, eqs. (15)-(16)).

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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SonarConfig:
    """Sonar ring of 001 §IV."""

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

    def axis_rad(self, k: int) -> float:
        """φ_s^k relative to the direction of motion, k = 1..k_s."""
        return -math.pi / 2 + (k - 1) * math.pi / (self.k_s - 1)


@dataclass(frozen=True)
class SubRegion:
    """Angular sub-region R_v relative to the heading: [lo, hi] (rad, CCW) and its η (m)."""

    v: int
    lo_rad: float
    hi_rad: float
    eta_m: float


def sub_regions(cfg: SonarConfig, rho_m) -> list[SubRegion]:
    """Eq. (15) of 001: the sub-regions and η_R^v for ranges ρ_s^k (metres, k = 1..k_s)."""
    rho = [min(float(r) + cfg.sensor_offset_m, cfg.d_e_m) if float(r) < cfg.d_e_m else cfg.d_e_m
           for r in rho_m]
    if len(rho) != cfg.k_s:
        raise ValueError(f"expected {cfg.k_s} sonar ranges, got {len(rho)}")
    half = cfg.a_g_rad / 2
    lo = [cfg.axis_rad(k) - half for k in range(1, cfg.k_s + 1)]
    hi = [cfg.axis_rad(k) + half for k in range(1, cfg.k_s + 1)]
    if cfg.a_g_rad <= math.pi / (cfg.k_s - 1):
        return [SubRegion(k + 1, lo[k], hi[k], rho[k]) for k in range(cfg.k_s)]
    out = []
    tol = cfg.shared_echo_tol_m

    def shared(a: int, b: int) -> bool:
        return (tol is not None and 0 <= b < cfg.k_s and rho[a] < cfg.d_e_m
                and abs(rho[a] - rho[b]) <= tol)

    for k in range(cfg.k_s):  # k is 0-based here: sensor S_{k+1}
        start = hi[k - 1] if k > 0 else lo[k]
        end = lo[k + 1] if k + 1 < cfg.k_s else hi[k]
        alone = cfg.d_e_m if shared(k, k - 1) or shared(k, k + 1) else rho[k]
        out.append(SubRegion(2 * k + 1, start, end, alone))
        if k + 1 < cfg.k_s:
            out.append(SubRegion(2 * k + 2, lo[k + 1], hi[k], max(rho[k], rho[k + 1])))
    return out


@dataclass(frozen=True)
class InfeasibleRegion:
    """Eq. (16) of 001 in the world frame: sector seen from the sensing position (ox, oy)."""

    ox: float
    oy: float
    lo_rad: float  # world direction of the clockwise boundary line
    hi_rad: float  # world direction of the counter-clockwise boundary line
    eta_m: float
    r_r_m: float
    # Ours (SonarConfig.arc_angle_bound): eq. (16)'s wedge stands for the echo arc grown by the
    # safety circle R_r, but for the narrow sub-regions of eq. (15) its apex Q_r lies 0.8-1.5 m
    # behind the sensing position, so its band η ± R_r also covers a strip R_r wide beside and
    # behind the robot (points 0.2 m from it, away from the echo). Every point within R_r of
    # the arc is seen from the sensing position within asin(R_r / η) of the arc's angles; the
    # bound keeps only those, so it never frees a point that is within R_r of the echo.
    arc_bound: bool = False

    @property
    def bound_half_rad(self) -> float:
        """Half-angle (about the bisector, from the sensing position) of the arc grown by R_r;
        π when η <= R_r (the robot is within R_r of the echo: no bound)."""
        if self.eta_m <= self.r_r_m:
            return math.pi
        return self.half_angle + math.asin(self.r_r_m / self.eta_m)

    @property
    def half_angle(self) -> float:
        """Half the angular width."""
        return 0.5 * (self.hi_rad - self.lo_rad)

    @property
    def apex(self) -> tuple[float, float]:
        """Q_r: the outward-shifted boundary lines meet on the bisector behind the origin."""
        mid = 0.5 * (self.lo_rad + self.hi_rad)
        back = self.r_r_m / math.sin(self.half_angle)
        return self.ox - back * math.cos(mid), self.oy - back * math.sin(mid)

    def contains(self, x, y) -> np.ndarray:
        """Eq. (16): True where (x, y) lies in the infeasible region (arrays broadcast)."""
        qx, qy = self.apex
        mid = 0.5 * (self.lo_rad + self.hi_rad)
        # θ_n within [θ_l, θ_r] <=> angle between (P − Q_r) and the bisector <= half-angle
        px, py = np.asarray(x) - qx, np.asarray(y) - qy
        along = px * math.cos(mid) + py * math.sin(mid)
        across = -px * math.sin(mid) + py * math.cos(mid)
        in_angle = (along > 0) & (np.abs(across) <= along * math.tan(self.half_angle))
        d = np.hypot(np.asarray(x) - self.ox, np.asarray(y) - self.oy)
        in_range = (d >= self.eta_m - self.r_r_m) & (d <= self.eta_m + self.r_r_m)
        if self.arc_bound and self.bound_half_rad < math.pi:
            ox, oy = np.asarray(x) - self.ox, np.asarray(y) - self.oy
            a = np.arctan2(-ox * math.sin(mid) + oy * math.cos(mid),
                           ox * math.cos(mid) + oy * math.sin(mid))
            in_angle = in_angle & (np.abs(a) <= self.bound_half_rad)
        return in_angle & in_range


@dataclass(frozen=True)
class SonarScan:
    """Result of turning one sonar reading into infeasible regions."""

    regions: list[InfeasibleRegion]
    dropped: int  # readings that were not valid numbers >= 0 and were treated as "no echo"


def infeasible_regions(cfg: SonarConfig, position_xy_m, heading_rad: float,
                       sonar_mm) -> SonarScan:
    """Infeasible regions (world frame) of one sonar reading taken at a pose.

    ``sonar_mm[k-1]`` is the range of S_k in millimetres (telemetry); values of D_e or more mean
    no echo. Readings that are negative or not numbers are counted in ``dropped`` and ignored.
    """
    if len(sonar_mm) != cfg.k_s:
        raise ValueError(f"expected {cfg.k_s} sonar ranges (mm), got {len(sonar_mm)}")
    rho, dropped = [], 0
    for r in sonar_mm:
        try:
            val = float(r)
        except (TypeError, ValueError):
            val = float("nan")
        if not math.isfinite(val) or val < 0:
            dropped += 1
            val = cfg.d_e_m * 1000.0
        rho.append(val / 1000.0)
    ox, oy = (float(v) for v in position_xy_m)
    regions = [InfeasibleRegion(ox, oy, heading_rad + sr.lo_rad, heading_rad + sr.hi_rad,
                                sr.eta_m, cfg.r_r_m, cfg.arc_angle_bound)
               for sr in sub_regions(cfg, rho) if sr.eta_m < cfg.d_e_m]
    return SonarScan(regions, dropped)


def any_region_contains(regions: list[InfeasibleRegion], x, y) -> np.ndarray:
    """Eq. (16) for many regions at once: True where (x, y) lies in at least one of them."""
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    if not regions:
        return np.zeros(np.broadcast(x, y).shape, dtype=bool)
    shape = (-1,) + (1,) * np.broadcast(x, y).ndim
    mid = np.array([0.5 * (r.lo_rad + r.hi_rad) for r in regions]).reshape(shape)
    tan_half = np.array([math.tan(r.half_angle) for r in regions]).reshape(shape)
    apex = np.array([r.apex for r in regions])
    qx, qy = apex[:, 0].reshape(shape), apex[:, 1].reshape(shape)
    ox = np.array([r.ox for r in regions]).reshape(shape)
    oy = np.array([r.oy for r in regions]).reshape(shape)
    lo = np.array([r.eta_m - r.r_r_m for r in regions]).reshape(shape)
    hi = np.array([r.eta_m + r.r_r_m for r in regions]).reshape(shape)
    c, s = np.cos(mid), np.sin(mid)
    px, py = x - qx, y - qy
    along = px * c + py * s
    across = np.abs(py * c - px * s)
    d2 = (x - ox) ** 2 + (y - oy) ** 2
    inside = (along > 0) & (across <= along * tan_half) & (d2 >= np.maximum(lo, 0.0) ** 2) \
        & (d2 <= hi**2)
    if any(r.arc_bound for r in regions):
        bound = np.array([r.bound_half_rad if r.arc_bound else math.pi
                          for r in regions]).reshape(shape)
        rx, ry = x - ox, y - oy
        ang = np.abs(np.arctan2(ry * c - rx * s, rx * c + ry * s))
        inside &= (bound >= math.pi) | (ang <= bound)
    return inside.any(axis=0)
