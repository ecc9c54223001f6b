"""The eye-in-hand camera's frames raw on a Unix socket, for a host program without a JPEG decoder
(``mobigrasp sim --raw-frames PATH``; the C host reads it with ``--camera unix:PATH``).

Every client that connects receives each new frame as one message: a 32-byte header, then the
pixels (docs/porting.md, "The raw-frame endpoint"). All fields little-endian:

====== ===== ==========================================================================
offset bytes field
====== ===== ==========================================================================
0      4     magic ``MGRF``
4      2     version, 1
6      2     format: 1 RGB (3 bytes a pixel, R first), 2 grey (1 byte a pixel)
8      2     width (320)
10     2     height (240)
12     4     seq: the frame's number, from 0 (a gap: frames this client missed)
16     8     capture_us: simulated µs at which the camera took the frame
24     4     nbytes: width x height x bytes a pixel (rows top to bottom, no padding)
28     4     0 (reserved)
====== ===== ==========================================================================

The camera gives RGB, so format is 1. A slow client skips frames (it always gets the newest,
whole) instead of holding the simulation back; one thread per client, as the MJPEG server.
The socket's file is created by the server and removed when it closes; an existing file at
PATH is refused (never deleted), as a port in use is.
"""

from __future__ import annotations

import os
import socket
import struct
import threading
from pathlib import Path
from typing import Any

MAGIC = b"MGRF"
VERSION = 1
FORMAT_RGB, FORMAT_GREY = 1, 2
HEADER = struct.Struct("<4sHHHHIqII")  # 32 bytes


class RawFramesPathInUse(OSError):
    """Something is already at the socket's path (not removed: mobigrasp did not create it)."""


def header(fmt: int, width: int, height: int, seq: int, capture_us: int, nbytes: int) -> bytes:
    """The 32 bytes that precede a frame's pixels."""
    return HEADER.pack(MAGIC, VERSION, fmt, width, height, seq & 0xFFFFFFFF, capture_us, nbytes,
                       0)


class RawFrameServer:
    """The newest frame, sent to every client of the Unix socket at ``path``."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        if os.path.lexists(self.path):
            raise RawFramesPathInUse(f"--raw-frames {self.path}: something is already there "
                                     f"(remove it or choose another path)")
        self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            self._sock.bind(str(self.path))
        except OSError as exc:
            self._sock.close()
            raise RawFramesPathInUse(f"--raw-frames {self.path}: {exc.strerror}") from exc
        self._sock.listen(4)
        self._cond = threading.Condition()
        self._seq = -1
        self._message: bytes = b""
        self._closed = False
        self.frames_published = 0
        self.messages_sent = 0
        self._clients: list[socket.socket] = []
        self._threads: list[threading.Thread] = []
        self._accepter = threading.Thread(target=self._accept, daemon=True, name="raw-frames")
        self._accepter.start()

    @property
    def url(self) -> str:
        """``unix:PATH``, as the C host's ``--camera`` takes it."""
        return f"unix:{self.path}"

    def publish(self, rgb: Any, capture_us: int) -> None:
        """A new frame (an H x W x 3 uint8 RGB array) taken at ``capture_us`` simulated."""
        h, w = int(rgb.shape[0]), int(rgb.shape[1])
        pixels = rgb.tobytes()
        with self._cond:
            self._seq += 1
            self._message = header(FORMAT_RGB, w, h, self._seq, capture_us, len(pixels)) + pixels
            self.frames_published += 1
            self._cond.notify_all()

    def _accept(self) -> None:
        while True:
            try:
                conn, _ = self._sock.accept()
            except OSError:
                return  # closed
            with self._cond:
                if self._closed:
                    conn.close()
                    return
                self._clients.append(conn)
            t = threading.Thread(target=self._serve, args=(conn,), daemon=True,
                                 name="raw-frames-client")
            self._threads.append(t)
            t.start()

    def _serve(self, conn: socket.socket) -> None:
        sent = [-1]
        try:
            while True:
                with self._cond:
                    self._cond.wait_for(lambda: self._seq > sent[0] or self._closed)
                    if self._closed:
                        return
                    sent[0], message = self._seq, self._message
                conn.sendall(message)
                self.messages_sent += 1
        except OSError:
            return  # the client went away
        finally:
            conn.close()

    def close(self) -> None:
        """Stop serving, end the clients' streams and remove the socket's file."""
        with self._cond:
            if self._closed:
                return
            self._closed = True
            self._cond.notify_all()
            clients = list(self._clients)
        for c in clients:
            try:
                c.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
        try:
            self._sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self._sock.close()
        self._accepter.join(timeout=2.0)
        for t in self._threads:
            t.join(timeout=2.0)
        try:
            self.path.unlink()
        except FileNotFoundError:
            pass
