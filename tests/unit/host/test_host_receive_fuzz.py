"""The host never crashes on in-spec MCU -> host traffic (docs/protocol.md §4): every message
type with every field anywhere in its wire range, extremes included (servo_us 0 = "off"), into
HostApp in process. No exception, no command out of its limits, and the odd values counted."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host.app_factory import build_host_app
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.frame import FrameParser
from mobigrasp.protocol.joints import JOINTS

U16 = st.one_of(st.sampled_from([0, 1, 499, 500, 1500, 2500, 2501, 0xFFFE, 0xFFFF]),
                st.integers(0, 0xFFFF))
I32 = st.one_of(st.sampled_from([-2**31, -1, 0, 1, 2**31 - 1]), st.integers(-2**31, 2**31 - 1))
U32 = st.one_of(st.sampled_from([0, 1, 2**32 - 1]), st.integers(0, 2**32 - 1))
U8 = st.integers(0, 255)
TEXT = st.text(st.characters(min_codepoint=32, max_codepoint=126), max_size=16)

telemetry = st.builds(
    m.Telemetry, U32, I32, I32, st.tuples(*[U16] * 6), st.tuples(*[U16] * 5), U16, U16, U16, U16,
    U16)
mcu_messages = st.one_of(
    telemetry,
    st.builds(m.HelloAck, st.sampled_from([m.PROTOCOL_VERSION, 0, 2, 255]), TEXT, U16),
    st.builds(m.Heartbeat, U32),
    st.builds(m.Ack, U8),
    st.builds(m.Nack, U8, U8),
    st.builds(m.ParamValue, U16, I32),
    st.builds(m.Log, U16, st.text(st.characters(min_codepoint=32, max_codepoint=126),
                                  max_size=48)),
)


def _check_command(msg):
    """Every command the host sends lies within its limits; returns 1 (one command checked)."""
    if isinstance(msg, m.SetServos):
        assert msg.mode == m.SERVO_MODE_MRAD
        for j, t in zip(JOINTS[1:], msg.targets[1:], strict=True):
            assert j.lo <= t <= j.hi, (j.name, t)
        assert 0 <= msg.targets[0] <= 1000
    elif isinstance(msg, m.Gripper):
        assert 0 <= msg.close_permille <= 1000
    elif isinstance(msg, m.SetWheels):
        assert abs(msg.left_mmps) <= 1000 and abs(msg.right_mmps) <= 1000
    return 1


@examples(60)
@given(method=st.sampled_from(["000", "001", "002"]),
       plan=st.lists(st.tuples(mcu_messages, U8, st.integers(0, 40_000)), min_size=1,
                     max_size=25))
def test_host_app_takes_every_in_spec_mcu_message(method, plan):
    app = build_host_app({"method": method})
    out = FrameParser()
    rgb = np.zeros((240, 320, 3), dtype=np.uint8)
    t = 0
    sent = 0
    # a session first, so the task runs and commands flow
    app.on_uart(m.encode_message(m.HelloAck(m.PROTOCOL_VERSION, "fw", 15), 0), t)
    for k, (msg, seq, dt_us) in enumerate(plan):
        t += dt_us
        app.on_uart(m.encode_message(msg, seq), t)
        if k % 5 == 0:
            app.on_frame(k, t, t, rgb)
        app.advance_to(t)
        for _, wire in app.take_output(t + 1):
            for frame in out.feed(wire):
                sent += _check_command(m.decode_frame(frame))
    # past the first HELLO's wait (HostConfig.hello_wait_us) when no telemetry was in the plan
    app.advance_to(t + 200_000)
    for _, wire in app.take_output(t + 200_001):
        for frame in out.feed(wire):
            sent += _check_command(m.decode_frame(frame))
    assert sent > 0 and out.stats.crc_errors == 0  # the host kept talking
    odd = [tel for tel, _, _ in plan if isinstance(tel, m.Telemetry)
           and not all(500 <= p <= 2500 for p in tel.servo_us)]
    assert app.link.counters.odd_telemetry >= (1 if odd else 0)
    assert app.link.counters.odd_telemetry <= len(plan)


def test_servo_off_in_telemetry_is_counted_and_the_last_good_angle_kept():
    app = build_host_app({"method": "000"})
    app.on_uart(m.encode_message(m.HelloAck(m.PROTOCOL_VERSION, "fw", 15), 0), 0)
    good = m.Telemetry(1000, 0, 0, (1000, 1500, 1500, 1500, 1500, 1500), (0xFFFF,) * 5,
                       m.FLAG_HANDSHAKE, 0, 0, 0, 0)
    off = m.Telemetry(21000, 0, 0, (0, 1500, 1500, 0, 1500, 65535), (0xFFFF,) * 5,
                      m.FLAG_HANDSHAKE, 0, 0, 0, 0)
    app.on_uart(m.encode_message(good, 1), 1000)
    app.advance_to(2000)
    app.on_uart(m.encode_message(off, 2), 21000)
    app.advance_to(22000)
    assert app.link.counters.odd_telemetry == 1
    assert app.link.telemetry.servo_us == (1000, 1500, 1500, 1500, 1500, 1500)
    assert app.link.telemetry.time_us == 21000  # the rest of the frame is taken as it came
