"""The compact GRANT and DONE (cosim/lockstep.py kinds 6 and 7): the same messages as the JSON
ones once decoded, used only where they can say everything, and as strict about bad input."""

import io
import struct

import pytest

from mobigrasp.cosim import lockstep as ls

LOAD = {"window_us": 500_000, "windows": {}, "state": "APPROACH", "finished": False,
        "camera": True, "quiet_until": 2_040_000}


def _kind(raw: bytes) -> int:
    return raw[4]


def test_quiet_grant_and_done_go_compact_and_come_back_equal():
    g = ls.Grant(start_us=2_030_000, until_us=2_035_000, uart=((2_026_123, 51), (2_029_000, 7)))
    d = ls.Done(until_us=2_035_000, writes=((2_030_400, 12),), load=dict(LOAD))
    for msg, kind in ((g, ls.KIND_GRANT_COMPACT), (d, ls.KIND_DONE_COMPACT),
                      (ls.Grant(start_us=0, until_us=5000), ls.KIND_GRANT_COMPACT),
                      (ls.Done(until_us=5000, load={**LOAD, "state": "ÜBER"}),
                       ls.KIND_DONE_COMPACT)):
        raw = ls.encode(msg)
        assert _kind(raw) == kind
        assert ls.decode(raw) == msg
        assert ls.read_message(io.BytesIO(raw + b"rest")) == msg
    assert len(ls.encode(d)) < 80  # the JSON form is ~180 bytes


@pytest.mark.parametrize("msg, kind", [
    (ls.Grant(start_us=0, until_us=5000,
              frames=(ls.FrameBlob(1, 0, 0, 2, 1, 3, bytes(6)),)), ls.KIND_GRANT),
    (ls.Done(until_us=5000, events=({"ev": "x", "t_us": 1},), load=dict(LOAD)), ls.KIND_DONE),
    (ls.Done(until_us=5000, load={**LOAD, "windows": {"3": 0.25}}), ls.KIND_DONE),
    (ls.Done(until_us=5000, load={k: v for k, v in LOAD.items() if k != "camera"}),
     ls.KIND_DONE),
    (ls.Done(until_us=5000, load={**LOAD, "extra": 1}), ls.KIND_DONE),
    (ls.Done(until_us=5000, load={**LOAD, "finished": 0}), ls.KIND_DONE),
    (ls.Done(until_us=5000, load={**LOAD, "quiet_until": None}), ls.KIND_DONE),
    (ls.Done(until_us=5000, load={**LOAD, "state": "S" * 300}), ls.KIND_DONE),
    (ls.Done(until_us=5000, writes=((1 << 70, 1),), load=dict(LOAD)), ls.KIND_DONE),
    (ls.Grant(start_us=0, until_us=5000, uart=((10, 1 << 40),)), ls.KIND_GRANT),
])
def test_what_the_compact_form_cannot_say_goes_as_json(msg, kind):
    raw = ls.encode(msg)
    assert _kind(raw) == kind
    assert ls.decode(raw) == msg


def _compact_done(until=5000, quiet=9000, window=500_000, finished=0, camera=1, state=b"S",
                  writes=((100, 2),)) -> bytes:
    body = (struct.pack("<qqqBBBI", until, quiet, window, finished, camera, len(state),
                        len(writes)) + state + b"".join(struct.pack("<qI", *w) for w in writes))
    return ls.HEADER.pack(ls.MAGIC, ls.KIND_DONE_COMPACT, len(body), 0) + body


def _compact_grant(start=0, until=5000, uart=()) -> bytes:
    body = struct.pack("<qqI", start, until, len(uart)) + b"".join(
        struct.pack("<qI", *c) for c in uart)
    return ls.HEADER.pack(ls.MAGIC, ls.KIND_GRANT_COMPACT, len(body), 0) + body


@pytest.mark.parametrize("uart", [(), ((4990, 3),), ((4990, 3), (4995, 200))])
def test_the_compact_wire_bytes_are_the_documented_layout(uart):
    # header, fixed part, then (state name and) chunks: what encode packs must stay this
    assert ls.encode(ls.Grant(start_us=0, until_us=5000, uart=uart)) == _compact_grant(uart=uart)
    load = {**LOAD, "window_us": 500_000, "quiet_until": 9000, "finished": False,
            "camera": True, "state": "S"}
    assert ls.encode(ls.Done(until_us=5000, writes=uart, load=load)) == _compact_done(
        writes=uart)


def test_decoded_compact_messages_are_whole_frozen_dataclasses():
    # the decoder builds them without __init__ (protocol/frozen.py): every field is there
    for msg in (ls.Grant(start_us=10, until_us=5000, uart=((20, 1),)),
                ls.Done(until_us=5000, writes=((100, 2),), load=dict(LOAD))):
        back = ls.decode(ls.encode(msg))
        assert type(back) is type(msg) and vars(back) == vars(msg) and back == msg
        with pytest.raises(AttributeError):
            back.until_us = 1
    # built skips __init__: a __post_init__ (a check) added to either class would be skipped
    assert not hasattr(ls.Grant, "__post_init__") and not hasattr(ls.Done, "__post_init__")


@pytest.mark.parametrize("raw, match", [
    (_compact_done()[:-1], "length|bytes"),
    (_compact_done() + b"x", "length"),
    (_compact_done(writes=((100, 2), (50, 1))), "backwards"),
    (_compact_done(writes=((-1, 2),)), "negative"),
    (_compact_done(until=-5), "until_us"),
    (_compact_done(finished=2), "flags"),
    (_compact_done(state=b"\xff\xfe"), "UTF-8"),
    (ls.HEADER.pack(ls.MAGIC, ls.KIND_GRANT_COMPACT, 4, 0) + bytes(4), "GRANT"),
    (ls.HEADER.pack(ls.MAGIC, ls.KIND_GRANT_COMPACT, 20, 0) + struct.pack("<qqI", 10, 5, 0),
     "quantum"),
    (ls.HEADER.pack(ls.MAGIC, ls.KIND_GRANT_COMPACT, 20, 1) + struct.pack("<qqI", 0, 5, 0)
     + b"x", "blob"),
])
def test_corrupt_compact_messages_are_refused(raw, match):
    with pytest.raises(ls.LockstepError, match=match):
        ls.decode(raw)


def test_a_compact_message_cut_short_on_the_stream_is_a_closed_peer():
    raw = ls.encode(ls.Done(until_us=5000, writes=((100, 2),), load=dict(LOAD)))
    with pytest.raises(ls.LockstepClosed):
        ls.read_message(io.BytesIO(raw[:-3]))
