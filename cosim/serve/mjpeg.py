"""The eye-in-hand camera as an IP camera serves it: MJPEG over HTTP on 127.0.0.1.

``GET /stream.mjpg`` answers ``multipart/x-mixed-replace`` with one JPEG part per new frame (at
the rate frames are published: the camera's, 15 fps at ``--speed 1``), which
``cv2.VideoCapture("http://127.0.0.1:PORT/stream.mjpg")`` opens as a video (its FFmpeg backend
reads the ``mpjpeg`` format). ``GET /frame.png`` answers the latest frame as a PNG. Every client
has its own thread (stdlib ThreadingHTTPServer); a frame is encoded once, by the first client
that wants it, so the simulation's thread only hands the array over. A slow client skips frames
instead of holding the simulation back. Bound to 127.0.0.1 only: nothing is served to the
network.
"""

from __future__ import annotations

import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

BOUNDARY = "mobigrasp-frame"
JPEG_QUALITY = 90
HOST = "127.0.0.1"


class CameraPortInUse(OSError):
    """The camera port could not be bound (another server has it)."""


class _Frames:
    """The latest frame, its number and its encodings (made on first request)."""

    def __init__(self) -> None:
        self.cond = threading.Condition()
        self.seq = -1
        self.rgb: Any = None
        self._encoded: dict[str, bytes] = {}
        self.closed = False

    def publish(self, rgb: Any) -> None:
        with self.cond:
            self.rgb = rgb
            self.seq += 1
            self._encoded = {}
            self.cond.notify_all()

    def encoded(self, ext: str) -> tuple[int, bytes | None]:
        """(seq, bytes) of the latest frame as ``.jpg`` or ``.png``; (-1, None) before any."""
        import cv2

        with self.cond:
            seq, rgb, cache = self.seq, self.rgb, self._encoded
            data = cache.get(ext)
        if rgb is None:
            return -1, None
        if data is None:
            params = [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY] if ext == ".jpg" else []
            ok, buf = cv2.imencode(ext, cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR), params)
            data = buf.tobytes() if ok else b""
            with self.cond:
                if self.seq == seq:
                    self._encoded[ext] = data
        return seq, data

    def wait_newer(self, seq: int, timeout_s: float) -> bool:
        """Wait until a frame after ``seq`` is published (or the server closes)."""
        with self.cond:
            return self.cond.wait_for(lambda: self.seq > seq or self.closed, timeout_s) \
                and not self.closed


class _Handler(BaseHTTPRequestHandler):
    server_version = "mobigrasp-camera/1"
    protocol_version = "HTTP/1.0"

    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 (stdlib signature)
        """Quiet: the simulation's stderr is for the run."""

    def do_GET(self) -> None:
        frames: _Frames = self.server.frames  # type: ignore[attr-defined]
        path = self.path.split("?", 1)[0]
        if path == "/stream.mjpg":
            self._stream(frames)
        elif path == "/frame.png":
            frames.wait_newer(-1, 5.0)
            _, data = frames.encoded(".png")
            if not data:
                self.send_error(503, "no frame yet")
                return
            self.send_response(200)
            self.send_header("Content-Type", "image/png")
            self.send_header("Content-Length", str(len(data)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(data)
        else:
            self.send_error(404, "only /stream.mjpg and /frame.png")

    def _stream(self, frames: _Frames) -> None:
        self.send_response(200)
        self.send_header("Content-Type", f"multipart/x-mixed-replace; boundary={BOUNDARY}")
        self.send_header("Cache-Control", "no-store")
        self.send_header("Connection", "close")
        self.end_headers()
        seq = -1
        try:
            while frames.wait_newer(seq, 1.0) or not frames.closed:
                if frames.seq <= seq:
                    continue  # timed out waiting (the simulation paused): wait again
                seq, data = frames.encoded(".jpg")
                if not data:
                    continue
                self.wfile.write(f"--{BOUNDARY}\r\nContent-Type: image/jpeg\r\n"
                                 f"Content-Length: {len(data)}\r\n\r\n".encode() + data + b"\r\n")
                self.wfile.flush()
                self.server.parts_sent += 1  # type: ignore[attr-defined]
        except (BrokenPipeError, ConnectionResetError):
            return  # the client went away


class CameraServer:
    """The HTTP server in a thread; :meth:`publish` hands it each new frame (RGB uint8)."""

    def __init__(self, port: int = 0) -> None:
        if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
            raise ValueError(f"camera port must be an integer in [0, 65535], got {port!r}")
        self.frames = _Frames()
        try:
            self._server = ThreadingHTTPServer((HOST, port), _Handler)
        except OSError as exc:
            raise CameraPortInUse(f"camera port {port} on {HOST}: {exc.strerror or exc}") \
                from exc
        self._server.daemon_threads = True
        self._server.frames = self.frames  # type: ignore[attr-defined]
        self._server.parts_sent = 0  # type: ignore[attr-defined]
        self.host: str = self._server.server_address[0]
        self.port: int = self._server.server_address[1]
        self.url = f"http://{HOST}:{self.port}/stream.mjpg"
        self.png_url = f"http://{HOST}:{self.port}/frame.png"
        self._thread = threading.Thread(target=self._server.serve_forever,
                                        kwargs={"poll_interval": 0.1}, daemon=True,
                                        name="camera-http")
        self._thread.start()

    def publish(self, rgb: Any) -> None:
        """The camera's newest frame."""
        self.frames.publish(rgb)

    @property
    def frames_published(self) -> int:
        """How many frames were published."""
        return self.frames.seq + 1

    @property
    def parts_sent(self) -> int:
        """JPEG parts written to stream clients, all clients together."""
        return self._server.parts_sent  # type: ignore[attr-defined]

    def close(self) -> None:
        """Stop serving; streams end (a second call does nothing)."""
        if self.frames.closed:
            return
        with self.frames.cond:
            self.frames.closed = True
            self.frames.cond.notify_all()
        self._server.shutdown()
        self._server.server_close()
        self._thread.join()
