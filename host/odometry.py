"""Integer wheel odometry of the differential-drive base from cumulative encoder ticks.

Conventions (docs/conventions.md): 1024 ticks per wheel revolution, wheel radius 40 mm, track
l_w = 300 mm, world frame x east / y north, heading counter-clockwise from +x.

Wheel travel is computed from the *cumulative* tick counts (s = ticks · 2π·40 mm / 1024, in µm
with a Q16 constant), so rounding never accumulates in the travelled distance. For a
differential drive without slip the heading is path independent, θ = θ0 + (s_r − s_l) / l_w, so it
is also computed from the cumulative distances (micro-radians). Position is integrated with the
midpoint heading of each update: x += d·cos θ_mid, y += d·sin θ_mid (Q12 sine/cosine from
:mod:`host.fixedpoint`). Encoder counters are int32 on the wire and are unwrapped modulo 2^32.
An update whose tick jump is impossible for the wheel speed limit is counted in ``dropped`` and
used only to re-synchronise the counters (the motion in it is lost, not invented).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.fixedpoint import cos_q12, div_round, sin_q12

TICKS_PER_REV = 1024
WHEEL_RADIUS_UM = 40_000
TRACK_UM = 300_000
# µm of travel per tick in Q16 (2π·40000/1024 = 245.437 µm); a constant in flash on the board.
UM_PER_TICK_Q16 = round(2 * math.pi * WHEEL_RADIUS_UM / TICKS_PER_REV * 65536)
URAD_PER_TURN = 6_283_185
MAX_WHEEL_SPEED_MM_S = 1500  # faster than any command (SetWheels is limited to 1000 mm/s)

UPDATE_OPS = OpCounts(alu=40, muls32=8, divs=3, luts=4, branches=6)


def _wrap32(delta: int) -> int:
    return ((int(delta) + (1 << 31)) & 0xFFFFFFFF) - (1 << 31)


def wrap_urad(a: int) -> int:
    """Angle in µrad wrapped to [−π, π)."""
    return (int(a) + URAD_PER_TURN // 2) % URAD_PER_TURN - URAD_PER_TURN // 2


@dataclass(frozen=True)
class Pose:
    """Integer pose and speeds of the base."""

    x_um: int
    y_um: int
    heading_mrad: int  # wrapped to [−3142, 3141]
    speed_mm_s: int
    yaw_rate_mrad_s: int

    @property
    def x_mm(self) -> int:
        """x rounded to mm."""
        return div_round(self.x_um, 1000)

    @property
    def y_mm(self) -> int:
        """y rounded to mm."""
        return div_round(self.y_um, 1000)


class Odometry:
    """Dead reckoning from (t_us, enc_left, enc_right) telemetry samples."""

    def __init__(self, x_um: int = 0, y_um: int = 0, heading_mrad: int = 0) -> None:
        self.reset(x_um, y_um, heading_mrad)
        self.dropped = 0

    def reset(self, x_um: int, y_um: int, heading_mrad: int) -> None:
        """Set the pose; the next update only re-synchronises the counters."""
        # position accumulators in µm · 2^13 (the Q12 product of a *sum* of two wheel travels),
        # so that no rounding happens per update
        self._x_acc = int(x_um) << 13
        self._y_acc = int(y_um) << 13
        self._theta0_urad = int(heading_mrad) * 1000
        self._ticks_l = 0  # unwrapped cumulative ticks since reset
        self._ticks_r = 0
        self._raw: tuple[int, int] | None = None
        self._t_us: int | None = None
        self._s_l_um = 0
        self._s_r_um = 0
        self._speed_mm_s = 0
        self._yaw_rate_mrad_s = 0

    def resync(self) -> None:
        """The MCU reset: its clock and encoder counters restarted from 0. Keep the pose and
        take the next sample as the new reference (without this every later sample looks
        "from the past" and the pose froze for the rest of the run: docs/cosim.md "Measured",
        T9)."""
        x_acc, y_acc, heading = self._x_acc, self._y_acc, self.heading_urad
        self.reset(0, 0, 0)  # (leaves the dropped count alone)
        self._x_acc, self._y_acc, self._theta0_urad = x_acc, y_acc, heading

    def _heading_urad(self, s_l_um: int, s_r_um: int) -> int:
        return self._theta0_urad + div_round((s_r_um - s_l_um) * 1_000_000, TRACK_UM)

    @property
    def heading_urad(self) -> int:
        """Heading in µrad, not wrapped."""
        return self._heading_urad(self._s_l_um, self._s_r_um)

    @property
    def pose(self) -> Pose:
        """The present pose estimate."""
        return self._pose(self.heading_urad)

    def _pose(self, heading_urad: int) -> Pose:
        """The pose with the present heading already computed (update has it)."""
        half = 1 << 12
        return Pose((self._x_acc + half) >> 13, (self._y_acc + half) >> 13,
                    div_round(wrap_urad(heading_urad), 1000), self._speed_mm_s,
                    self._yaw_rate_mrad_s)

    def update(self, t_us: int, enc_left: int, enc_right: int) -> Pose:
        """Advance with one telemetry sample (cumulative int32 encoder counts)."""
        t_us, enc_left, enc_right = int(t_us), int(enc_left), int(enc_right)
        if self._raw is None or self._t_us is None:
            self._raw, self._t_us = (enc_left, enc_right), t_us
            return self.pose
        dt_us = t_us - self._t_us
        if dt_us < 0:
            self.dropped += 1  # telemetry from the past: ignore it entirely
            return self.pose
        dl = _wrap32(enc_left - self._raw[0])
        dr = _wrap32(enc_right - self._raw[1])
        self._raw, self._t_us = (enc_left, enc_right), t_us
        # ticks a wheel at MAX_WHEEL_SPEED_MM_S could make in dt, plus slack of 4 ticks
        limit = MAX_WHEEL_SPEED_MM_S * dt_us * TICKS_PER_REV // 251_327_000 + 4
        if abs(dl) > limit or abs(dr) > limit:
            self.dropped += 1
            return self.pose
        theta_prev = self._heading_urad(self._s_l_um, self._s_r_um)
        self._ticks_l += dl
        self._ticks_r += dr
        s_l = (self._ticks_l * UM_PER_TICK_Q16 + (1 << 15)) >> 16
        s_r = (self._ticks_r * UM_PER_TICK_Q16 + (1 << 15)) >> 16
        d_l, d_r = s_l - self._s_l_um, s_r - self._s_r_um
        self._s_l_um, self._s_r_um = s_l, s_r
        theta = self._heading_urad(s_l, s_r)
        mid_mrad = div_round(theta_prev + theta, 2000)
        d_sum = d_l + d_r  # twice the travel of the base centre
        self._x_acc += d_sum * cos_q12(mid_mrad)
        self._y_acc += d_sum * sin_q12(mid_mrad)
        if dt_us > 0:
            self._speed_mm_s = div_round(d_sum * 500, dt_us)
            self._yaw_rate_mrad_s = div_round((theta - theta_prev) * 1000, dt_us)
        return self._pose(theta)
