"""host.vision.frame_key.frame_bytes: the bytes of ``tobytes()``, without the copy only for a
C-contiguous view of the whole of an immutable ``bytes`` object (a frame from the lockstep
channel)."""

from __future__ import annotations

import numpy as np

from mobigrasp.host.app_factory import _LastFrameMemo
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.vision.frame_key import frame_bytes


def _frame(seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 256, (6, 8, 3), dtype=np.uint8)


def test_a_frame_from_bytes_is_keyed_by_those_bytes():
    pixels = _frame().tobytes()
    rgb = np.frombuffer(pixels, dtype=np.uint8).reshape(6, 8, 3)  # as drivers/lockstep.py does
    assert frame_bytes(rgb) is pixels
    assert frame_bytes(rgb.view(np.int8)) is pixels  # (the memo keys the dtype separately)


def test_anything_else_is_copied_and_always_equals_tobytes():
    pixels = _frame(1).tobytes()
    flat = np.frombuffer(pixels, dtype=np.uint8)
    whole = flat.reshape(6, 8, 3)
    cases = [
        _frame(2),  # owns its memory (writable: may change after the call)
        flat[3:3 + 2 * 8 * 3].reshape(2, 8, 3),  # part of the bytes
        flat[:-3].reshape(-1, 3),  # the start of the bytes only
        whole[:, ::2],  # not contiguous
        whole[::-1],  # not C order
        np.frombuffer(bytearray(pixels), dtype=np.uint8).reshape(6, 8, 3),  # mutable buffer
        np.asfortranarray(_frame(3)),
    ]
    for a in cases:
        got = frame_bytes(a)
        assert type(got) is bytes and got == a.tobytes() and got is not pixels


def test_the_memo_keys_bytes_backed_frames_by_contents():
    calls = []

    def det(rgb):
        calls.append(1)
        return int(rgb.sum()), OpCounts(alu=len(calls))

    memo = _LastFrameMemo(det)
    img = _frame(4)
    a = np.frombuffer(img.tobytes(), dtype=np.uint8).reshape(img.shape)
    b = np.frombuffer(img.tobytes(), dtype=np.uint8).reshape(img.shape)  # other bytes, equal
    assert memo(a) == memo(b) == memo(img) and len(calls) == 1
    img[0, 0, 0] ^= 1
    c = np.frombuffer(img.tobytes(), dtype=np.uint8).reshape(img.shape)
    assert memo(c)[0] == int(img.sum()) and len(calls) == 2
