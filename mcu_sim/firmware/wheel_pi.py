"""Wheel speed PI control on encoder counts at 100 Hz, integer only.

Per wheel, every 10 ms: the target speed in mm/s becomes encoder ticks per 10 ms in Q8, using the
wheel of docs/conventions.md (radius 40 mm, 1024 quadrature counts per revolution, so
1 mm/s = 1024 / (2 pi 40) / 100 ticks per 10 ms = 10.430 in Q8); the measured ticks of the last
10 ms (Q8) are subtracted, and the duty is ``(kp e + ki sum(e)) >> 8`` clamped to -255..255 with
the integral clamped so that ``ki x integral`` alone cannot exceed full duty (anti-windup).
A zero target with nothing to correct leaves the bridge off and the integral empty, so a parked
robot does not creep on encoder noise.
"""

from __future__ import annotations

MMPS_TO_TICKS_Q8_NUM = 10430  # ticks per 10 ms in Q8 per mm/s, x 1000
MMPS_TO_TICKS_Q8_DEN = 1000
DUTY_MAX = 255
CONTROL_PERIOD_US = 10_000
# Ticks counted in one period are clamped to this before the Q8 shift, so that kp (<= 1000)
# times the error stays inside the C port's int32 whatever the encoder does; beyond it (over
# 60 revolutions per 10 ms) the duty saturates either way, so nothing else changes.
DELTA_MAX_TICKS = 8191


def mmps_to_ticks_q8(mmps: int) -> int:
    """Wheel speed in mm/s to encoder ticks per 10 ms in Q8 (truncating toward zero)."""
    v = abs(mmps) * MMPS_TO_TICKS_Q8_NUM // MMPS_TO_TICKS_Q8_DEN
    return v if mmps >= 0 else -v


class WheelPi:
    """State of one wheel's controller (int32 / int16 variables in C)."""

    def __init__(self) -> None:
        self.target_mmps = 0
        self.target_q8 = 0
        self.integral = 0
        self.last_count = 0
        self.duty = 0

    def reset(self, count: int) -> None:
        """Forget the integral and start measuring from ``count``."""
        self.target_mmps = 0
        self.target_q8 = 0
        self.integral = 0
        self.last_count = count
        self.duty = 0

    def set_target(self, mmps: int) -> None:
        """New speed target in mm/s (already clamped by the caller)."""
        self.target_mmps = mmps
        self.target_q8 = mmps_to_ticks_q8(mmps)

    def stop(self, count: int) -> None:
        """Zero target, zero duty, empty integral (STOP, watchdog)."""
        self.reset(count)

    def update(self, count: int, kp: int, ki: int) -> int:
        """One 10 ms step with the encoder count now; returns the new signed duty."""
        delta = count - self.last_count
        if delta > DELTA_MAX_TICKS:
            delta = DELTA_MAX_TICKS
        elif delta < -DELTA_MAX_TICKS:
            delta = -DELTA_MAX_TICKS
        measured_q8 = delta << 8
        self.last_count = count
        err = self.target_q8 - measured_q8
        if self.target_q8 == 0 and measured_q8 == 0:
            self.integral = 0
            self.duty = 0
            return 0
        self.integral += err
        if ki > 0:
            limit = (DUTY_MAX << 8) // ki
            if self.integral > limit:
                self.integral = limit
            elif self.integral < -limit:
                self.integral = -limit
        else:
            self.integral = 0
        u = (kp * err + ki * self.integral) >> 8
        if u > DUTY_MAX:
            u = DUTY_MAX
        elif u < -DUTY_MAX:
            u = -DUTY_MAX
        self.duty = u
        return u
