"""Ultrasonic sonar ring of paper 001 by ray casts in the pymunk space.

Sensor k (k = 1..k_s) points at ``phi_k = -pi/2 + (k - 1) pi / (k_s - 1)`` from the heading
(section III.C.2 of 001; k = 1 is the right side, since angles are counter-clockwise), sits on the
footprint circle in that direction, and sees a cone of total width A_g = 1.05 rad up to
D_e = 2.5 m. The cone is sampled by ``rays_per_cone`` segment queries spread evenly across it
(both edges included); the reading is the nearest hit, i.e. the distance from the sensor to the
closest surface any ray meets, like the first echo of a real sonar. No hit -> None (no echo; the
paper's rho = D_e convention is the planner's business).

Options, all seeded by a numpy Generator: Gaussian range noise ``noise_std_m`` and a
``dropout_p`` probability that a sensor returns None on a reading.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pymunk
from pymunk._chipmunk_cffi import ffi as _ffi
from pymunk._chipmunk_cffi import lib as _lib

from .base import FOOTPRINT_RADIUS_M


@dataclass(frozen=True)
class SonarConfig:
    """Ring geometry and error options."""

    k_s: int = 5
    A_g: float = 1.05
    D_e: float = 2.5
    rays_per_cone: int = 9
    mount_radius_m: float = FOOTPRINT_RADIUS_M
    noise_std_m: float = 0.0
    dropout_p: float = 0.0

    def __post_init__(self):
        if self.k_s < 2:
            raise ValueError(f"SonarConfig.k_s: need at least 2 sensors, got {self.k_s}")
        if self.rays_per_cone < 1 or self.A_g <= 0 or self.D_e <= 0:
            raise ValueError("SonarConfig: rays_per_cone >= 1, A_g > 0 and D_e > 0 required")
        if self.noise_std_m < 0 or not 0.0 <= self.dropout_p <= 1.0:
            raise ValueError("SonarConfig: noise_std_m >= 0 and dropout_p in [0, 1] required")


def sensor_angles(k_s: int) -> list[float]:
    """phi_k of 001 for k = 1..k_s, relative to the heading (rad, counter-clockwise)."""
    return [-math.pi / 2 + (k - 1) * math.pi / (k_s - 1) for k in range(1, k_s + 1)]


class SonarRing:
    """k_s sonars; ``read(space, pose)`` returns one range (m) or None per sensor."""

    def __init__(self, config: SonarConfig, rng: np.random.Generator, ignore_group: int = 1):
        self.config = config
        self.rng = rng
        self.angles = sensor_angles(config.k_s)
        n = config.rays_per_cone
        half = config.A_g / 2
        self.ray_offsets = [0.0] if n == 1 else [-half + i * config.A_g / (n - 1)
                                                  for i in range(n)]
        # Rays skip the robot's own shape (same non-zero group).
        self.filter = pymunk.ShapeFilter(group=ignore_group)
        self._info = _ffi.new("cpSegmentQueryInfo *")

    def _range_exact(self, space: pymunk.Space, pose: tuple[float, float, float], phi: float
                     ) -> float | None:
        x, y, h = pose
        c = self.config
        a = h + phi
        sx = x + c.mount_radius_m * math.cos(a)
        sy = y + c.mount_radius_m * math.sin(a)
        best: float | None = None
        # chipmunk's cpSpaceSegmentQueryFirst directly: the same query as
        # Space.segment_query_first without building a result object per ray
        info, query, sp, filt = self._info, _lib.cpSpaceSegmentQueryFirst, space._space, \
            self.filter
        null = _ffi.NULL
        for off in self.ray_offsets:
            ex = sx + c.D_e * math.cos(a + off)
            ey = sy + c.D_e * math.sin(a + off)
            if query(sp, (sx, sy), (ex, ey), 0.0, filt, info) != null:
                d = info.alpha * c.D_e
                if best is None or d < best:
                    best = d
        return best

    def _noisy(self, d: float | None) -> float | None:
        c = self.config
        if c.noise_std_m == 0.0 and c.dropout_p == 0.0:
            return d
        noise = float(self.rng.normal(0.0, c.noise_std_m)) if c.noise_std_m > 0 else 0.0
        drop = c.dropout_p > 0 and float(self.rng.random()) < c.dropout_p
        if d is None or drop:
            return None
        return min(max(d + noise, 0.0), c.D_e)

    def read_exact(self, space: pymunk.Space, pose: tuple[float, float, float]
                   ) -> list[float | None]:
        """Noise-free nearest-hit ranges from the sensors at the base pose (x, y, heading)."""
        return [self._range_exact(space, pose, phi) for phi in self.angles]

    def read(self, space: pymunk.Space, pose: tuple[float, float, float]) -> list[float | None]:
        """Ranges of all sensors with the configured noise and dropout."""
        return [self._noisy(d) for d in self.read_exact(space, pose)]

    def read_one(self, space: pymunk.Space, pose: tuple[float, float, float], index: int
                 ) -> float | None:
        """Range of sensor ``index`` (0-based: k = index + 1) with noise and dropout.

        The MCU fires its sonars one after another, so the rig asks for one at a time.
        """
        if not isinstance(index, int) or not 0 <= index < len(self.angles):
            raise ValueError(f"sonar index must be an int 0..{len(self.angles) - 1}, "
                             f"got {index!r}")
        return self._noisy(self._range_exact(space, pose, self.angles[index]))
