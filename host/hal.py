"""Hardware abstraction of the S3C2440 program: the interfaces host code talks to.

As in ArduPilot's AP_HAL, host code never touches a device or the wall clock directly; a host
driver implements these (mobigrasp.drivers.lockstep: time granted by the rig, frames from the
GRANTs; mobigrasp.drivers.realtime: the board's free-running clock, an OpenCV camera, a serial
device) and one wiring place (``mobigrasp host``) chooses it. Time is integer microseconds,
owned by whoever drives the host.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Protocol

import numpy as np


class Clock(ABC):
    """Source of the host's notion of time, in integer microseconds."""

    @abstractmethod
    def now_us(self) -> int:
        """Current time in microseconds."""


class ManualClock(Clock):
    """A clock moved only by its owner: the in-process backend and the one tests use."""

    def __init__(self, start_us: int = 0) -> None:
        self._now_us = int(start_us)

    def now_us(self) -> int:
        """Current time in microseconds."""
        return self._now_us

    def advance_us(self, delta_us: int) -> int:
        """Move time forward by ``delta_us`` (never backward); returns the new time."""
        if delta_us < 0:
            raise ValueError(f"delta_us must be >= 0, got {delta_us}")
        self._now_us += int(delta_us)
        return self._now_us

    def set_us(self, t_us: int) -> None:
        """Jump to ``t_us``; refuses to go backwards."""
        if t_us < self._now_us:
            raise ValueError(f"clock cannot go back from {self._now_us} to {t_us} us")
        self._now_us = int(t_us)


@dataclass(frozen=True)
class CameraFrame:
    """One camera image as the host receives it: pixels and the simulated capture time only."""

    seq: int
    capture_us: int
    rgb: np.ndarray  # uint8, shape (240, 320, 3)


class Camera(ABC):
    """Frame source: the rendered eye-in-hand camera, or a real OpenCV capture."""

    @abstractmethod
    def poll(self) -> CameraFrame | None:
        """Return the newest frame not yet returned, or None."""

    @abstractmethod
    def close(self) -> None:
        """Release the source."""


class SerialPort(Protocol):
    """The UART to the ATmega128 (a link transport: mobigrasp.link.registry.open_transport)."""

    def read(self) -> bytes:
        """What arrived since the last read, without waiting (b"" for nothing)."""

    def write(self, data: bytes) -> None:
        """Send ``data``."""

    def wait_readable(self, timeout_s: float) -> bool:
        """Wait up to ``timeout_s`` for bytes to read; whether there are some."""

    def close(self) -> None:
        """Close the port."""
