""""Wheels in the air": the tiny motor model that spins the encoders when the MCU runs alone.

Used by ``mobigrasp mcu`` (no world attached) and the MCU benchmark, so that the wheel PI loop
sees encoder counts that answer its duty. Each wheel is a first-order DC motor without load:
the speed tends to ``duty / 255 x free_speed_mmps`` with time constant ``tau_us``; the position
is integrated and reported in quadrature counts (1024 per revolution of a 40 mm wheel, from
docs/conventions.md). This is a plant, not firmware, so it may use floats.
"""

from __future__ import annotations

import math

TICKS_PER_REV = 1024
WHEEL_RADIUS_MM = 40.0
TICKS_PER_MM = TICKS_PER_REV / (2.0 * math.pi * WHEEL_RADIUS_MM)


class WheelsInTheAir:
    """Two unloaded wheel motors: signed duty in, cumulative encoder counts out."""

    def __init__(self, free_speed_mmps: float = 800.0, tau_us: int = 80_000) -> None:
        if free_speed_mmps <= 0 or tau_us <= 0:
            raise ValueError("free_speed_mmps and tau_us must be > 0")
        self.free_speed_mmps = free_speed_mmps
        self.tau_us = tau_us
        self.speed_mmps = [0.0, 0.0]
        self.position_mm = [0.0, 0.0]
        self.t_us = 0  # the plant interface's clock (step_to)
        self._duty = (0, 0)

    def step(self, duty: tuple[int, int], dt_us: int) -> tuple[int, int]:
        """Advance ``dt_us`` with the given signed duties; returns the encoder counts after it."""
        alpha = 1.0 - math.exp(-dt_us / self.tau_us)
        for side in (0, 1):
            d = max(-255, min(255, int(duty[side])))
            target = d / 255.0 * self.free_speed_mmps
            v0 = self.speed_mmps[side]
            v1 = v0 + (target - v0) * alpha
            self.position_mm[side] += 0.5 * (v0 + v1) * dt_us * 1e-6
            self.speed_mmps[side] = v1
        return self.ticks()

    def ticks(self) -> tuple[int, int]:
        """Cumulative encoder counts (left, right)."""
        return (math.floor(self.position_mm[0] * TICKS_PER_MM),
                math.floor(self.position_mm[1] * TICKS_PER_MM))

    # ---- the rig's plant interface (mobigrasp.cosim.plant.Plant) ---------------------------
    def step_to(self, t_us: int) -> None:
        """Advance to ``t_us`` with the duties last set (nothing happens backwards)."""
        if t_us > self.t_us:
            self.step(self._duty, t_us - self.t_us)
            self.t_us = t_us

    def set_wheel_duty(self, left: int, right: int) -> None:
        """The duties the next :meth:`step_to` applies."""
        self._duty = (int(left), int(right))

    def set_servo_pulse_us(self, ch: int, pulse_us: int) -> None:
        """Servos in the air move nothing this plant models."""

    def encoder_ticks(self) -> tuple[int, int]:
        """Cumulative encoder counts (left, right)."""
        return self.ticks()

    def sonar_range_m(self, index: int) -> float | None:
        """No obstacle in the air: no echo."""
        return None

    def capture(self, t_us: int) -> None:
        """No camera."""
        return None
