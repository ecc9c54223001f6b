"""Frames out of band: the shared-memory ring (cosim/frame_ring.py), the codec's shared frames."""

import os

import pytest

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.frame_ring import FrameRing, FrameRingReader


def _frame(seq, fill, w=8, h=4):
    return ls.FrameBlob(seq=seq, capture_us=1000 * seq, arrival_us=1000 * seq + 5000, width=w,
                        height=h, channels=3, pixels=bytes([fill]) * (w * h * 3))


def test_grant_frames_cross_through_the_ring_and_equal_the_inline_ones(tmp_path):
    ring, reader = FrameRing(slots=2, slot_bytes=8 * 4 * 3, directory=str(tmp_path)), \
        FrameRingReader()
    try:
        g = ls.Grant(start_us=5000, until_us=10_000, uart=((4000, 3),),
                     frames=(_frame(1, 7), _frame(2, 9)))
        wire = ls.encode(g, frame_sink=ring.put)
        assert ls.decode_header(wire[:ls.HEADER.size])[2] == 0  # no pixels in the message
        with pytest.raises(ls.LockstepError, match="shared memory"):
            ls.decode(wire)  # no reader on this end
        kind, meta_len, blob_len = ls.decode_header(wire[:ls.HEADER.size])
        body = wire[ls.HEADER.size:]
        back = ls.decode_body(kind, body[:meta_len], body[meta_len:], frame_source=reader)
        assert back == g
        # a frame too big for a slot goes inline
        big = ls.Grant(start_us=0, until_us=5000, frames=(_frame(3, 1, w=16),))
        assert ls.decode(ls.encode(big, frame_sink=ring.put)) == big
    finally:
        reader.close()
        ring.close()
    assert not os.path.exists(ring.path)


def test_slots_come_round_in_turn_with_their_user():
    ring = FrameRing(slots=3, slot_bytes=4)
    try:
        where = [ring.put(b"abcd", user=k) for k in range(4)]
        assert [w["offset"] for w in where] == [0, 4, 8, 0]
        assert ring.user == [3, 1, 2] and ring.next_slot() == 1
        reader = FrameRingReader()
        assert reader(where[3], 4) == b"abcd"
        reader.close()
    finally:
        ring.close()


@pytest.mark.parametrize("where, n, match", [
    ("not a dict", 4, "must be an object"),
    ({"path": "/nonexistent/ring", "offset": 0, "nbytes": 4}, 4, "ring"),
    ({"path": None, "offset": 0, "nbytes": 4}, 4, "bad shared frame"),
    ({"offset": 0, "nbytes": 5}, 4, "bad shared frame"),
    ({"offset": -4, "nbytes": 4}, 4, "bad shared frame"),
    ({"offset": 8, "nbytes": 4}, 4, "outside the ring"),
])
def test_bad_shared_frame_references_are_clear_errors(where, n, match):
    ring = FrameRing(slots=2, slot_bytes=4)
    try:
        if isinstance(where, dict) and "path" not in where:
            where = {"path": ring.path, **where}
        with pytest.raises(ls.LockstepError, match=match):
            FrameRingReader()(where, n)
    finally:
        ring.close()
