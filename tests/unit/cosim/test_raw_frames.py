"""The raw-frame endpoint of ``mobigrasp sim`` (cosim/serve/raw_frames.py): the 32-byte header
of docs/porting.md, then the pixels; the socket's file removed at the end, a taken path kept."""

import socket
import struct
import tempfile
from pathlib import Path

import numpy as np
import pytest

from mobigrasp.cosim.serve.raw_frames import RawFrameServer, RawFramesPathInUse


def _read(conn: socket.socket, n: int) -> bytes:
    out = b""
    while len(out) < n:
        chunk = conn.recv(n - len(out))
        assert chunk, f"stream ended after {len(out)} of {n} bytes"
        out += chunk
    return out


def test_a_frame_is_its_header_then_its_pixels():
    with tempfile.TemporaryDirectory(prefix="mg-rf-") as tmp:
        path = Path(tmp) / "f.sock"
        server = RawFrameServer(path)
        try:
            conn = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            conn.connect(str(path))
            conn.settimeout(30)
            rgb = np.arange(240 * 320 * 3, dtype=np.uint32).astype(np.uint8).reshape(240, 320, 3)
            server.publish(rgb, 1_234_567)
            head = _read(conn, 32)
            magic, version, fmt, w, h, seq, capture_us, nbytes, reserved = struct.unpack(
                "<4sHHHHIqII", head)
            assert (magic, version, fmt, w, h, seq) == (b"MGRF", 1, 1, 320, 240, 0)
            assert (capture_us, nbytes, reserved) == (1_234_567, 320 * 240 * 3, 0)
            assert _read(conn, nbytes) == rgb.tobytes()
            conn.close()
        finally:
            server.close()
        assert not path.exists()


def test_a_path_already_taken_is_refused_and_kept(tmp_path):
    taken = tmp_path / "x.sock"
    taken.write_text("someone's")
    with pytest.raises(RawFramesPathInUse, match="something is already there"):
        RawFrameServer(taken)
    assert taken.read_text() == "someone's"
