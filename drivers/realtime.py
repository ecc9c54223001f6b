"""The real board's host driver: a free-running clock, an OpenCV camera and a serial device.

The host program (mobigrasp.host.app.HostApp) is the same object as under the rig; here its time
is the wall clock since start (:class:`WallClock`), its frames come from ``cv2.VideoCapture``
(:class:`OpenCvCamera`, a device index, a video file or a URL such as ``mobigrasp sim``'s MJPEG
stream) and its UART is whatever is on the port (``mobigrasp mcu``'s pty or a real ATmega128).
:func:`run` is the loop: read the UART, hand over a frame, step the program, write its output.
"""

from __future__ import annotations

import threading
import time
from typing import Any

from mobigrasp.host.hal import Camera, CameraFrame, Clock, SerialPort
from mobigrasp.link.base import LinkClosed

CAMERA_FPS = 15  # a video file is read at the camera rate


class WallClock(Clock):
    """Microseconds of wall time since the clock was made (monotonic)."""

    def __init__(self) -> None:
        self.t0 = time.monotonic()

    def now_us(self) -> int:
        """Microseconds since start."""
        return int((time.monotonic() - self.t0) * 1e6)


class OpenCvCamera(Camera):
    """Frames from cv2.VideoCapture, stamped with ``clock``'s time.

    A live source (a device index, or a URL) is read by a thread as fast as it delivers, keeping
    only the newest frame: a host loop that falls behind for a moment then skips frames, as a
    CAMIF does, instead of working through a growing backlog of old ones (whose scene lags the
    arm further each time). A video file is read one frame per 1/15 s of the clock."""

    def __init__(self, source: str, clock: Clock) -> None:
        import cv2

        self._cv2 = cv2
        self._clock = clock
        self.live = source.isdigit() or "://" in source
        self.cap = cv2.VideoCapture(int(source) if source.isdigit() else source)
        if not self.cap.isOpened():
            raise ValueError(f"cannot open camera source {source!r}")
        self.seq = 0
        self._next_file_us = 0.0
        self._latest: CameraFrame | None = None  # from the reader thread
        self._taken = -1
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        if self.live:
            self._thread = threading.Thread(target=self._reader, daemon=True, name="camera")
            self._thread.start()

    def _convert(self, bgr: Any) -> Any:
        return self._cv2.resize(self._cv2.cvtColor(bgr, self._cv2.COLOR_BGR2RGB), (320, 240))

    def _reader(self) -> None:
        while not self._stop.is_set():
            ok, bgr = self.cap.read()
            if not ok:
                return  # the stream ended
            arrival_us = self._clock.now_us()
            rgb = self._convert(bgr)
            with self._lock:
                self._latest = CameraFrame(self.seq, arrival_us, rgb)
                self.seq += 1

    def poll(self) -> CameraFrame | None:
        """A frame not handed out before, or None (for a file: none before its time)."""
        if not self.live:
            now_us = self._clock.now_us()
            if now_us < self._next_file_us:
                return None
            ok, bgr = self.cap.read()
            if not ok:
                return None
            self._next_file_us = now_us + 1e6 / CAMERA_FPS
            self.seq += 1
            return CameraFrame(self.seq - 1, now_us, self._convert(bgr))
        with self._lock:
            got = self._latest
        if got is None or got.seq == self._taken:
            return None
        self._taken = got.seq
        return got

    def close(self) -> None:
        """Stop the reader and release the capture."""
        self._stop.set()
        if self._thread is not None:
            # a read blocked on a stream that went quiet ends when the server closes it; the
            # capture is not released under a read still running (the thread is a daemon)
            self._thread.join(timeout=2.0)
            if self._thread.is_alive():
                return
        self.cap.release()


def run(app: Any, port: SerialPort, clock: Clock, camera: Camera | None = None) -> str:
    """Drive ``app`` until its task ends; why it stopped: ``"finished"``, ``"port_closed"``
    (the MCU or its pty vanished) or ``"interrupted"`` (Ctrl-C)."""
    try:
        while not app.finished:
            now_us = clock.now_us()
            data = port.read()
            if data:
                app.on_uart(data, now_us)
            frame = camera.poll() if camera is not None else None
            if frame is not None:
                app.on_frame(frame.seq, frame.capture_us, max(frame.capture_us, app.now_us),
                             frame.rgb)
            app.advance_to(now_us + 1)
            # the detectors now, between steps (the pose they read was taken with the frame;
            # in wall time there is no rig to keep waiting, so no reason to defer them)
            app.resolve_vision()
            out = app.take_output(now_us + 1)
            if out:
                port.write(b"".join(w for _, w in out))
            port.wait_readable(0.002)
    except LinkClosed:
        return "port_closed"
    except KeyboardInterrupt:
        return "interrupted"
    return "finished"
