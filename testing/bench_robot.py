"""The robot fixture's interface on a real robot: a serial device and a camera (pytest-embedded's
way of pointing one test at hardware by an option).

``port`` is the device (``--robot-port /dev/ttyUSB0``); :meth:`frame` reads the camera through
OpenCV (``--robot-camera 0`` for a camera index, or a video file, an image sequence such as
``shots/%03d.png`` or a stream URL). What only a simulation has (the world's ground truth, a clock
the test moves, the MCU's side of the line) skips the test with the reason, so a test written for
the emulated robot runs on the bench as far as the bench can take it.
"""

from __future__ import annotations

from typing import Any

import pytest


def camera_source(text: str | None) -> int | str | None:
    """``--robot-camera``'s value for cv2.VideoCapture: an index for digits, else the text."""
    if text is None:
        return None
    return int(text) if text.isdigit() else text


class BenchRobot:
    """A real robot behind ``port`` and ``camera`` (see the module docstring)."""

    def __init__(self, scenario: str, port: str, camera: int | str | None = None) -> None:
        self.scenario = scenario
        self.port = port
        self.camera = camera
        self._capture: Any = None

    @staticmethod
    def _bench_skip(what: str) -> None:
        pytest.skip(f"{what} needs the emulated robot; this test runs on the bench "
                    f"(--robot-port)")

    def frame(self) -> Any:
        """The camera's next frame, uint8 H x W x 3 BGR (cv2.VideoCapture.read)."""
        if self.camera is None:
            pytest.skip("frame(): no camera given (--robot-camera INDEX|FILE)")
        import cv2

        if self._capture is None:
            self._capture = cv2.VideoCapture(self.camera)
            if not self._capture.isOpened():
                raise RuntimeError(f"--robot-camera {self.camera!r}: OpenCV cannot open it")
        ok, img = self._capture.read()
        if not ok:
            raise RuntimeError(f"--robot-camera {self.camera!r}: no frame")
        return img

    def advance_ms(self, n: int) -> None:
        """Skips: a real robot's clock is the wall clock."""
        self._bench_skip("advance_ms() (a clock the test moves)")

    @property
    def now_us(self) -> int:
        """Skips: a real robot's clock is the wall clock."""
        self._bench_skip("now_us (a clock the test moves)")
        return 0

    def expect(self, predicate, within_ms: int, step_ms: int = 1, between=None) -> int:
        """Skips: ``expect`` waits in simulated time."""
        self._bench_skip("expect() (waiting in simulated time)")
        return 0

    def truth(self) -> Any:
        """Skips: a real world has no ground truth to read."""
        self._bench_skip("truth() (the world's ground truth)")

    def telemetry(self) -> list:
        """Skips: on the bench the line is your host's alone."""
        self._bench_skip("telemetry() (the MCU's side of the line)")
        return []

    def nacks(self) -> list:
        """Skips: on the bench the line is your host's alone."""
        self._bench_skip("nacks() (the MCU's side of the line)")
        return []

    def close(self) -> None:
        """Release the camera."""
        if self._capture is not None:
            self._capture.release()
            self._capture = None
