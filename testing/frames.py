"""The camera of ``mobigrasp sim`` as numpy images: ``/frame.png`` and the MJPEG stream.

The server (mobigrasp.cosim.serve.mjpeg) answers ``GET /frame.png`` with the latest frame as a
lossless PNG and ``GET /stream.mjpg`` with one JPEG per new frame (``multipart/x-mixed-replace``).
Both come back as OpenCV does it: uint8 H x W x 3, BGR.
"""

from __future__ import annotations

import urllib.request
from typing import Any

import cv2
import numpy as np


def _decode(data: bytes, what: str) -> np.ndarray:
    img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    if img is None:
        raise ValueError(f"{what}: not an image ({len(data)} bytes)")
    return img


def frame_url(camera_url: str) -> str:
    """``/frame.png`` beside the stream URL ``sim`` prints."""
    base = camera_url.rsplit("/", 1)[0] if camera_url.endswith(".mjpg") else camera_url
    return base.rstrip("/") + "/frame.png"


def read_frame(camera_url: str, timeout_s: float = 10.0) -> np.ndarray:
    """The latest frame (lossless), from the stream URL or the server's base URL."""
    url = frame_url(camera_url)
    with urllib.request.urlopen(url, timeout=timeout_s) as resp:  # noqa: S310 (127.0.0.1)
        return _decode(resp.read(), url)


class MjpegReader:
    """The frames of ``/stream.mjpg`` in order, one per :meth:`read` (blocks until the next)."""

    def __init__(self, camera_url: str, timeout_s: float = 10.0) -> None:
        self.url = camera_url
        self._resp: Any = urllib.request.urlopen(camera_url, timeout=timeout_s)  # noqa: S310

    def read(self) -> np.ndarray:
        """The next part's image; EOFError when the stream has ended."""
        length = None
        while True:  # the part's headers, up to the blank line
            line = self._resp.readline()
            if not line:
                raise EOFError(f"{self.url}: the stream ended")
            text = line.decode("latin-1").strip()
            if text.lower().startswith("content-length:"):
                length = int(text.split(":", 1)[1])
            elif not text and length is not None:
                break
        return _decode(self._resp.read(length), self.url)

    def close(self) -> None:
        """Close the connection."""
        self._resp.close()
