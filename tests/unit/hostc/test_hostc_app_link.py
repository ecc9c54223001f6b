"""The C host's protocol client (hostc/app_link.c on the firmware's codec) against
host/app_link.py: the same bytes from the MCU (valid, corrupted, split anywhere) and the same
commands at the same times give the same wire bytes out, telemetry, session state, events and
counters."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.host.app_link import HostLink
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.frame import encode_raw

FFI, C = hostc.lib()
U16 = st.integers(0, 0xFFFF)
SEQ = st.integers(0, 24)  # the seqs a short session has used: ACKs that find their command
TEXT = st.text(st.characters(min_codepoint=0x20, max_codepoint=0x7E), max_size=16)

MCU_MESSAGES = st.one_of(
    st.builds(m.Telemetry, st.integers(0, 0xFFFFFFFF), st.integers(-(1 << 31), (1 << 31) - 1),
              st.integers(-(1 << 31), (1 << 31) - 1),
              st.tuples(*[st.integers(400, 2600) | st.sampled_from([0, 1500])] * 6),
              st.tuples(*[U16] * 5),
              st.sampled_from([0, m.FLAG_HANDSHAKE, m.FLAG_RESET, m.FLAG_HANDSHAKE | 8]) | U16,
              U16, U16, U16, U16),
    st.builds(m.Ack, SEQ), st.builds(m.Nack, SEQ, st.integers(1, 7)),
    st.builds(m.HelloAck, st.sampled_from([1, 1, 2]), TEXT, U16),
    st.builds(m.Log, U16, TEXT), st.builds(m.ParamValue, U16, st.integers(-5, 5)))


@st.composite
def mcu_bytes(draw) -> bytes:
    """Wire bytes from the MCU: messages, frames of unknown types or bad lengths, garbage, and
    single-byte corruption."""
    parts = []
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["msg", "msg", "msg", "raw", "junk"]))
        if kind == "msg":
            parts.append(m.encode_message(draw(MCU_MESSAGES), draw(st.integers(0, 255))))
        elif kind == "raw":
            parts.append(encode_raw(draw(st.sampled_from([1, 1, 2])), draw(st.integers(0, 255)),
                                    draw(st.sampled_from([0x20, 0x40, 0x41, 0x77, 0x02])),
                                    draw(st.binary(max_size=50))))
        else:
            parts.append(draw(st.binary(max_size=12)))
    data = bytearray(b"".join(parts))
    if data and draw(st.booleans()):
        data[draw(st.integers(0, len(data) - 1))] ^= draw(st.integers(1, 255))
    return bytes(data)


OPS = st.one_of(
    st.tuples(st.just("rx"), mcu_bytes(), st.integers(1, 80)),
    st.tuples(st.just("servos"), st.lists(st.integers(-5000, 5000), min_size=6, max_size=6),
              st.integers(0, 0xFFFF)),
    st.tuples(st.just("wheels"), st.integers(-3000, 3000), st.integers(-3000, 3000)),
    st.tuples(st.just("gripper"), st.integers(-200, 1300), st.just(0)),
    st.tuples(st.sampled_from(["heartbeat", "stop", "hello", "service"]), st.just(0),
              st.just(0)),
    st.tuples(st.just("take"), st.integers(-30_000, 60_000), st.just(0)))


def _c_events(link) -> list[dict]:
    out = FFI.new("mg_link_event_t[32]")
    events = []
    for e in out[0:C.mg_link_take_events(link, out, 32)]:
        text = FFI.string(e.text).decode()
        base = {"t_us": e.t_us}
        if e.kind == C.MG_EV_MCU_RESET_SEEN:
            events.append({"ev": "mcu_reset_seen", **base, "why": text})
        elif e.kind == C.MG_EV_NACK:
            events.append({"ev": "nack", **base, "seq": e.seq, "reason": e.code})
        elif e.kind == C.MG_EV_HELLO_ACK:
            events.append({"ev": "hello_ack", **base, "firmware_id": text, "ok": bool(e.ok)})
        elif e.kind == C.MG_EV_MCU_LOG:
            events.append({"ev": "mcu_log", **base, "code": e.code, "text": text})
        else:
            events.append({"ev": "reliable_failed", **base, "seq": e.seq})
    return events


def _telemetry(link):
    if not link.has_telemetry:
        return None
    t = link.telemetry
    return m.Telemetry(t.time_us, t.enc_left, t.enc_right, tuple(t.servo_us), tuple(t.sonar_mm),
                       t.flags, t.crc_errors, t.overruns, t.limit_hits, t.watchdog_trips)


def _assert_same(c, py: HostLink) -> None:
    cnt = c.counters
    stats = py.stats()
    for name in ("tx_frames", "tx_bytes", "rx_frames", "rx_bytes", "decode_errors",
                 "retransmits", "reliable_failed", "nacks", "rejected_outputs",
                 "clamped_outputs", "telemetry", "odd_telemetry"):
        assert getattr(cnt, name) == stats[name], name
    for name, value in stats["parser"].items():
        assert getattr(c.parser.stats, name) == value, name
    assert _telemetry(c) == py.telemetry
    assert c.telemetry_us == py.telemetry_us
    assert bool(c.handshake_ok) == py.handshake_ok
    assert bool(C.mg_link_needs_hello(c)) == py.needs_hello
    assert c.mcu_resets == py.mcu_resets
    assert c.rx_bytes_since_take == py.rx_bytes_since_take
    assert c.gripper_permille == py.gripper_permille
    assert [c.reliable.slot[i].seq for i in range(c.reliable.n)] == py.reliable.in_flight()
    nxt = C.mg_link_next_send_us(c)
    assert (None if nxt < 0 else nxt) == py.next_send_us()
    assert _c_events(c) == py.events
    py.events = []


@examples(100)
@given(st.integers(1_000, 80_000), st.integers(0, 12),
       st.lists(st.tuples(st.integers(0, 30_000), OPS), min_size=20, max_size=60))
def test_protocol_client_sequence(timeout_us, retries, ops):
    _run(timeout_us, retries, ops)


RETRY_OPS = st.one_of(
    st.tuples(st.sampled_from(["service", "service", "hello", "stop"]), st.just(0), st.just(0)),
    st.tuples(st.just("gripper"), st.integers(0, 1000), st.just(0)),
    st.tuples(st.just("servos"), st.lists(st.integers(-3000, 3000), min_size=6, max_size=6),
              st.just(0)),
    st.tuples(st.just("take"), st.just(0), st.just(0)))


@examples(150)
@given(st.integers(1_000, 5_000), st.integers(0, 2),
       st.lists(st.tuples(st.integers(0, 6_000), RETRY_OPS), min_size=15, max_size=40))
def test_retransmissions_until_given_up(timeout_us, retries, ops):
    """No answers and few retries: resent frames, supersession of SetServos by a Gripper, and
    the seqs given up, in the same order at the same times."""
    _run(timeout_us, retries, ops)


def _run(timeout_us, retries, ops):
    py = HostLink(retransmit_timeout_us=timeout_us, max_retries=retries)
    c = FFI.new("mg_host_link_t *")
    C.mg_link_init(c, timeout_us, retries)
    chunks = FFI.new("mg_wire_chunk_t[48]")
    t_us = 0
    for dt, (op, a, b) in ops:
        t_us += dt
        if op == "rx":
            for i in range(0, len(a), b):
                C.mg_link_receive(c, a[i:i + b], len(a[i:i + b]), t_us)
                py.receive(a[i:i + b], t_us)
        elif op == "servos":
            assert C.mg_link_send_servos_mrad(c, a, t_us, b) == py.send_servos_mrad(a, t_us, b)
        elif op == "wheels":
            assert C.mg_link_send_wheels(c, a, b, t_us) == py.send_wheels(a, b, t_us)
        elif op == "gripper":
            assert C.mg_link_send_gripper(c, a, t_us) == py.send_gripper(a, t_us)
        elif op == "heartbeat":
            C.mg_link_send_heartbeat(c, t_us)
            py.send_heartbeat(t_us)
        elif op == "stop":
            C.mg_link_send_stop(c, t_us)
            py.send_stop(t_us)
        elif op == "hello":
            C.mg_link_hello(c, t_us)
            py.hello(t_us)
        elif op == "service":
            C.mg_link_service(c, t_us)
            py.service(t_us)
        else:
            n = C.mg_link_take_output(c, t_us + a, chunks, 48)
            got = [(ch.at_us, bytes(FFI.buffer(ch.wire, ch.len))) for ch in chunks[0:n]]
            assert got == py.take_output(t_us + a)
        _assert_same(c, py)
    assert c.outbox_dropped == 0 and c.events_dropped == 0
