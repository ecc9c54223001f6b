"""The C host's lockstep codec (hostc/lockstep.c, hostc/json.c) against cosim/lockstep.py: the
GRANTs and ENDs the rig writes decode to the same fields, and the HELLO, DONE and BYE the C
writes are the Python codec's bytes, so the rig cannot tell the hosts apart."""

from __future__ import annotations

import json

from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.cosim import lockstep as ls

FFI, C = hostc.lib()
T = st.integers(0, (1 << 62))
SETTINGS = examples(150)


@st.composite
def chunks(draw, max_size=6):
    times = sorted(draw(st.lists(T, max_size=max_size)))
    return tuple((t, draw(st.integers(0, 0xFFFFFFFF))) for t in times)


@st.composite
def grants(draw):
    start = draw(st.integers(0, 1 << 40))
    until = start + draw(st.integers(0, 1 << 20))
    frames = []
    for seq in range(draw(st.integers(0, 3))):
        w, h, c = draw(st.integers(1, 6)), draw(st.integers(1, 5)), draw(st.sampled_from([1, 3]))
        capture = draw(st.integers(0, until))
        frames.append(ls.FrameBlob(seq, capture, capture + draw(st.integers(0, 9000)), w, h, c,
                                   draw(st.binary(min_size=w * h * c, max_size=w * h * c))))
    return ls.Grant(start, until, draw(chunks()), tuple(frames))


def _decode(wire: bytes):
    kind, meta_len, blob_len = FFI.new("int32_t *"), FFI.new("uint32_t *"), FFI.new("uint32_t *")
    assert C.mg_ls_decode_header(wire[:13], kind, meta_len, blob_len) == 0
    assert 13 + meta_len[0] + blob_len[0] == len(wire)
    g = FFI.new("mg_ls_grant_t *")
    ok = C.mg_ls_decode_grant(kind[0], wire[13:13 + meta_len[0]], meta_len[0], blob_len[0], g)
    return ok, g, wire[13 + meta_len[0]:]


@SETTINGS
@given(grants(), st.booleans())
def test_grants_decode_to_the_same_fields(grant, shared):
    """Compact (no frames), JSON with the pixels in the blob, or in a frame ring."""
    ring = {}

    def sink(pixels):
        where = {"path": f"/dev/shm/ring-{len(ring)}", "offset": 100 * len(ring),
                 "nbytes": len(pixels)}
        ring[where["path"]] = pixels
        return where

    ok, g, blob = _decode(ls.encode(grant, frame_sink=sink if shared else None))
    assert ok == 0
    assert (g.start_us, g.until_us) == (grant.start_us, grant.until_us)
    assert [(c.t_us, c.nbytes) for c in g.uart[0:g.n_uart]] == list(grant.uart)
    assert g.n_frames == len(grant.frames)
    for f, want in zip(g.frames[0:g.n_frames], grant.frames, strict=True):
        assert (f.seq, f.capture_us, f.arrival_us, f.width, f.height, f.channels, f.nbytes) == (
            want.seq, want.capture_us, want.arrival_us, want.width, want.height,
            want.channels, len(want.pixels))
        if shared:
            assert f.shared == 1
            assert ring[FFI.string(f.path).decode()] == want.pixels
        else:
            assert f.shared == 0
            assert blob[f.offset:f.offset + f.nbytes] == want.pixels


@SETTINGS
@given(grants(), st.integers(0, 400), st.integers(1, 255))
def test_damaged_grants_are_refused_or_read_as_python_reads_them(grant, at, xor):
    """A byte of the metadata changed: C refuses the grant exactly when Python's decoder
    raises, and otherwise reads the same quantum."""
    wire = bytearray(ls.encode(grant))
    at = 13 + at % max(1, len(wire) - 13)
    if at >= len(wire):
        return
    wire[at] ^= xor
    try:
        want = ls.decode(bytes(wire))
    except (ls.LockstepError, ValueError):
        want = None
    kind, meta_len, blob_len = FFI.new("int32_t *"), FFI.new("uint32_t *"), FFI.new("uint32_t *")
    if C.mg_ls_decode_header(bytes(wire[:13]), kind, meta_len, blob_len) != 0:
        return
    g = FFI.new("mg_ls_grant_t *")
    meta = bytes(wire[13:13 + meta_len[0]])
    got = C.mg_ls_decode_grant(kind[0], meta, len(meta), blob_len[0], g)
    if not isinstance(want, ls.Grant):
        assert got != 0
    elif got == 0:
        assert (g.start_us, g.until_us) == (want.start_us, want.until_us)
        assert [(c.t_us, c.nbytes) for c in g.uart[0:g.n_uart]] == list(want.uart)


def test_end_and_hello_and_bye():
    e = FFI.new("mg_ls_end_t *")
    meta = ls.encode(ls.End(123456789, "scenario done: \"ok\" \u00e9"))[13:]
    assert C.mg_ls_decode_end(meta, len(meta), e) == 0
    assert (e.at_us, FFI.string(e.reason).decode()) == (123456789, "scenario done: \"ok\" \u00e9")
    out = FFI.new("uint8_t[4096]")
    n = C.mg_ls_encode_hello(out, 4096, b"mobigrasp-host")
    assert bytes(out[0:n]) == ls.encode(ls.Hello(host_id="mobigrasp-host"))
    stats = {"protocol": {"tx_bytes": 5}, "state": "DONE", "arm9_load_max": 0.25}
    text = json.dumps(stats, sort_keys=True, separators=(",", ":")).encode()
    n = C.mg_ls_encode_bye(out, 4096, text, len(text))
    assert bytes(out[0:n]) == ls.encode(ls.Bye(stats=stats))


EVENT = st.fixed_dictionaries({"ev": st.sampled_from(["state", "wheels", "detect"]),
                               "t_us": T, "why": st.text(max_size=8)})


@SETTINGS
@given(st.integers(0, 1 << 50), chunks(), st.lists(EVENT, max_size=3),
       st.sampled_from([500_000, 1_000_000, 250_000]),
       st.dictionaries(st.integers(0, 5000), st.integers(0, 1_000_000), max_size=4),
       st.text(st.characters(blacklist_categories=("Cs",), blacklist_characters="\x00"),
               max_size=20) | st.sampled_from(["INIT", "APPROACH", "DONE"]), st.booleans(),
       st.booleans(), T)
def test_done_bytes(until, writes, events, window, windows, state, finished, camera, quiet):
    """Compact without events or windows, JSON with them: the Python codec's bytes, the load
    windows printed as Python prints round(busy / window, 6)."""
    busy = {k: v * window // 1_000_000 for k, v in windows.items()}
    load = {"window_us": window, "state": state, "finished": finished, "camera": camera,
            "quiet_until": quiet,
            "windows": {str(k): round(b / window, 6) for k, b in busy.items()}}
    want = ls.encode(ls.Done(until, writes, tuple(events), load))
    ev_text = ",".join(json.dumps(e, sort_keys=True, separators=(",", ":")) for e in events)
    keep = [FFI.new("mg_ls_chunk_t[]", [(t, n) for t, n in writes] or [(0, 0)]),
            FFI.new("char[]", ev_text.encode()), FFI.new("char[]", state.encode()),
            FFI.new("int64_t[]", list(busy) or [0]),
            FFI.new("int64_t[]", [b * 1_000_000 // window for b in busy.values()] or [0])]
    d = FFI.new("mg_ls_done_t *", {
        "until_us": until, "n_writes": len(writes), "writes": keep[0],
        "n_events": len(events), "events": keep[1], "events_len": len(ev_text.encode()),
        "window_us": window, "n_windows": len(busy), "window_index": keep[3],
        "window_micro": keep[4], "state": keep[2], "finished": finished, "camera": camera,
        "quiet_until": quiet})
    out = FFI.new("uint8_t[65536]")
    n = C.mg_ls_encode_done(out, 65536, d)
    assert bytes(out[0:n]) == want
    assert ls.decode(want) == ls.decode(bytes(out[0:n]))


@SETTINGS
@given(st.integers(0, 10**12))
def test_micro_values_print_as_python_repr(v):
    out = FFI.new("char[64]")
    j = FFI.new("mg_json_t *")
    C.mg_json_init(j, out, 64)
    C.mg_json_micro(j, v)
    assert FFI.string(out, j.len).decode() == repr(round(v / 1_000_000, 6))


@SETTINGS
@given(st.text(max_size=30))
def test_strings_escape_as_python_json(s):
    raw = s.encode("utf-8", "surrogatepass")
    out = FFI.new("char[512]")
    j = FFI.new("mg_json_t *")
    C.mg_json_init(j, out, 512)
    C.mg_json_string(j, raw, len(raw))
    try:
        s.encode("utf-8")
    except UnicodeEncodeError:
        return  # a lone surrogate is not UTF-8: no C string carries it
    assert FFI.string(out, j.len).decode() == json.dumps(s)
