"""Float reference of 001's infeasible regions (eq. (16)) for the tests: the geometry of an
integer InfeasibleRegion (host/planning/sonar_regions.py) in metres and radians, and regions
made from metres and radians."""

from __future__ import annotations

import math

import numpy as np

from mobigrasp.host.planning.bezier_q import POS_PER_M
from mobigrasp.host.planning.sonar_regions import InfeasibleRegion


def region_m(ox: float, oy: float, lo: float, hi: float, eta: float, r_r: float,
             arc_bound: bool = False) -> InfeasibleRegion:
    """An InfeasibleRegion from metres and radians (rounded to its integers)."""
    q = POS_PER_M
    return InfeasibleRegion(round(ox * q), round(oy * q), round(lo * 1e6), round(hi * 1e6),
                            round(eta * q), round(r_r * q), bool(arc_bound))


def grown_m(reg: InfeasibleRegion, by_m: float) -> InfeasibleRegion:
    """The region with R_r grown by ``by_m`` metres."""
    return reg.grown(round(by_m * POS_PER_M))


class Ref:
    """A region's float geometry (metres, radians)."""

    def __init__(self, reg: InfeasibleRegion) -> None:
        q = POS_PER_M
        self.ox, self.oy = reg.ox_q4 / q, reg.oy_q4 / q
        self.lo_rad, self.hi_rad = reg.lo_urad / 1e6, reg.hi_urad / 1e6
        self.eta_m, self.r_r_m = reg.eta_q4 / q, reg.r_r_q4 / q
        self.arc_bound = reg.arc_bound

    @property
    def mid(self) -> float:
        return 0.5 * (self.lo_rad + self.hi_rad)

    @property
    def half_angle(self) -> float:
        return 0.5 * (self.hi_rad - self.lo_rad)

    @property
    def bound_half_rad(self) -> float:
        """Half-angle of the arc grown by R_r seen from the sensing position (π: no bound)."""
        if not self.arc_bound or self.eta_m <= self.r_r_m:
            return math.pi
        return self.half_angle + math.asin(self.r_r_m / self.eta_m)

    @property
    def apex(self) -> tuple[float, float]:
        back = self.r_r_m / math.sin(self.half_angle)
        return self.ox - back * math.cos(self.mid), self.oy - back * math.sin(self.mid)

    def arc_end(self, which: int) -> tuple[float, float]:
        a = self.lo_rad if which == 0 else self.hi_rad
        return self.ox + self.eta_m * math.cos(a), self.oy + self.eta_m * math.sin(a)

    def contains(self, x, y) -> np.ndarray:
        """Eq. (16) in floats (arrays broadcast)."""
        qx, qy = self.apex
        c, s = math.cos(self.mid), math.sin(self.mid)
        px, py = np.asarray(x) - qx, np.asarray(y) - qy
        along = px * c + py * s
        across = -px * s + py * c
        in_angle = (along > 0) & (np.abs(across) <= along * math.tan(self.half_angle))
        rx, ry = np.asarray(x) - self.ox, np.asarray(y) - self.oy
        d = np.hypot(rx, ry)
        in_range = (d >= self.eta_m - self.r_r_m) & (d <= self.eta_m + self.r_r_m)
        if self.bound_half_rad < math.pi:
            a = np.arctan2(-rx * s + ry * c, rx * c + ry * s)
            in_angle = in_angle & (np.abs(a) <= self.bound_half_rad)
        return in_angle & in_range


def any_region_contains(regions, x, y) -> np.ndarray:
    """Eq. (16) in floats for many regions: True where (x, y) lies in at least one."""
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    out = np.zeros(np.broadcast(x, y).shape, dtype=bool)
    for reg in regions:
        out |= Ref(reg).contains(x, y)
    return out


def inside_q(regions, x, y) -> np.ndarray:
    """Eq. (16) as the planners test it (the regions' integer words) at points in metres."""
    from mobigrasp.host.planning.bezier_q import geo_q, in_regions_q

    xq = np.rint(np.asarray(x, dtype=np.float64) * POS_PER_M).astype(np.int64)
    yq = np.rint(np.asarray(y, dtype=np.float64) * POS_PER_M).astype(np.int64)
    return in_regions_q(geo_q((0.0, 0.0), 0.0, regions), len(regions), xq, yq)
