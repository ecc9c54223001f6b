"""Ultrasonic range finders of paper 001 (five sonars): trigger pulse in, echo pulse out.

A sonar triggered at time t answers, ``ECHO_DELAY_US`` later (the module's 40 kHz burst), with an
echo pulse whose width is the round-trip time of sound: ``width = 2 d / 343 m/s`` (5.83 µs per mm).
Objects beyond ``MAX_RANGE_M`` = 2.5 m (the range of paper 001) give no echo at all, and the
firmware's timeout reports "no echo". The range comes from a provider the wiring sets,
``provider(index) -> metres | None`` (None: nothing in range, or sonar not fitted); a provider
that raises or returns a non-finite or negative value is counted in ``bad_readings`` and treated
as no echo, never a crash. Times are CPU cycles; the model computes both edges at trigger time.
"""

from __future__ import annotations

import math
from collections.abc import Callable

SPEED_OF_SOUND_MPS = 343.0
MAX_RANGE_M = 2.5
ECHO_DELAY_US = 250
MAX_SONARS = 5

Provider = Callable[[int], "float | None"]


def echo_width_us(distance_m: float) -> float:
    """Echo pulse width for an object at ``distance_m``: 2 d / c."""
    return 2.0 * distance_m / SPEED_OF_SOUND_MPS * 1e6


class SonarArray:
    """Up to five sonars sharing one trigger/echo interface; echo edges become interrupt events."""

    def __init__(self, count: int = MAX_SONARS, cycles_per_us: int = 16) -> None:
        if not 0 <= count <= MAX_SONARS:
            raise ValueError(f"sonar count must be 0..{MAX_SONARS}, got {count}")
        self.count = count
        self.cycles_per_us = cycles_per_us
        self.provider: Provider | None = None
        self.bad_readings = 0
        self.triggers = 0
        self.echo_events: list[tuple[int, int, int]] = []  # (cycle, index, level)

    def reset(self) -> None:
        """Forget echoes in flight (MCU reset)."""
        self.echo_events = []

    def _range_m(self, index: int) -> float | None:
        if self.provider is None or index >= self.count:
            return None
        try:
            d = self.provider(index)
        except Exception:  # a faulty world must not take the MCU down
            self.bad_readings += 1
            return None
        if d is None:
            return None
        try:
            d = float(d)
        except (TypeError, ValueError):
            self.bad_readings += 1
            return None
        if not math.isfinite(d) or d < 0.0:
            self.bad_readings += 1
            return None
        return d if d <= MAX_RANGE_M else None

    def trigger(self, index: int, cycle: int) -> None:
        """Trigger sonar ``index`` at ``cycle``; schedules echo edges if something is in range."""
        self.triggers += 1
        d = self._range_m(index)
        if d is None:
            return
        rise = cycle + ECHO_DELAY_US * self.cycles_per_us
        fall = rise + max(1, round(echo_width_us(d) * self.cycles_per_us))
        self.echo_events.append((rise, index, 1))
        self.echo_events.append((fall, index, 0))
        self.echo_events.sort()

    def next_event(self) -> int | None:
        """Cycle of the next echo edge, or None."""
        return self.echo_events[0][0] if self.echo_events else None

    def take_events_until(self, cycle: int) -> list[tuple[int, int, int]]:
        """Echo edges ``(cycle, index, level)`` at or before ``cycle``, in time order."""
        n = 0
        while n < len(self.echo_events) and self.echo_events[n][0] <= cycle:
            n += 1
        out, self.echo_events = self.echo_events[:n], self.echo_events[n:]
        return out
