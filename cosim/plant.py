"""The plant as the rig drives it: one interface for the world, the bench plant, the fault
wrapper and the test fakes (tests/contract/test_plant_contract.py runs on each).

The rig's coupling step (mobigrasp.cosim.rig) gives the plant the MCU's servo pulses and wheel
duties, steps it to the coupling time and reads the encoder counts back; the MCU's sonar reads
ask it for ranges; the camera captures frames at the camera rate.
"""

from __future__ import annotations

from typing import Any, Protocol


class Plant(Protocol):
    """What the rig needs of the plant."""

    def step_to(self, t_us: int) -> None:
        """Advance the plant to simulated time ``t_us`` (never backwards)."""

    def set_servo_pulse_us(self, ch: int, pulse_us: int) -> None:
        """Servo channel ``ch`` now receives pulses ``pulse_us`` wide."""

    def set_wheel_duty(self, left: int, right: int) -> None:
        """The motors' signed 8-bit PWM duties."""

    def encoder_ticks(self) -> tuple[int, int]:
        """Cumulative quadrature counts (left, right) now."""

    def sonar_range_m(self, index: int) -> float | None:
        """Range of sonar ``index`` in metres now, None without an echo (or no such sonar)."""

    def capture(self, t_us: int) -> Any:
        """The camera's frame now: a uint8 (H, W, 3) array, or None without a camera."""
