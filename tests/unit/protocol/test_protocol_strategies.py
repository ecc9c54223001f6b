"""Hypothesis strategies for protocol messages, shared by the protocol tests (imported by name).

The ranges here are written from the brief / docs/protocol.md, not read from protocol code, so a
wrong range in the code makes these tests fail.
"""

from hypothesis import strategies as st

from mobigrasp.protocol import messages as m

U8, U16, U32 = (0, 0xFF), (0, 0xFFFF), (0, 0xFFFFFFFF)
I32 = (-(2**31), 2**31 - 1)
ASCII = st.characters(min_codepoint=0x20, max_codepoint=0x7E)

# (class, payload size without text, [(field, lo, hi, count)], text field, text max)
TABLE = [
    (m.Hello, 3, [("proto_version", *U8, 1), ("capabilities", *U16, 1)], "host_id", 16),
    (m.HelloAck, 3, [("proto_version", *U8, 1), ("capabilities", *U16, 1)], "firmware_id", 16),
    (m.Heartbeat, 4, [("time_us", *U32, 1)], None, 0),
    (m.Gripper, 2, [("close_permille", 0, 1000, 1)], None, 0),
    (m.SetWheels, 4, [("left_mmps", -1000, 1000, 1), ("right_mmps", -1000, 1000, 1)], None, 0),
    (m.Stop, 0, [], None, 0),
    (m.Telemetry, 44, [
        ("time_us", *U32, 1), ("enc_left", *I32, 1), ("enc_right", *I32, 1),
        ("servo_us", *U16, 6), ("sonar_mm", *U16, 5), ("flags", *U16, 1),
        ("crc_errors", *U16, 1), ("overruns", *U16, 1), ("limit_hits", *U16, 1),
        ("watchdog_trips", *U16, 1)], None, 0),
    (m.ParamGet, 2, [("param_id", *U16, 1)], None, 0),
    (m.ParamSet, 6, [("param_id", *U16, 1), ("value", *I32, 1)], None, 0),
    (m.ParamValue, 6, [("param_id", *U16, 1), ("value", *I32, 1)], None, 0),
    (m.Ack, 1, [("acked_seq", *U8, 1)], None, 0),
    (m.Nack, 2, [("acked_seq", *U8, 1), ("reason", *U8, 1)], None, 0),
    (m.Log, 2, [("code", *U16, 1)], "text", 48),
]
SERVO_RANGES = {0: (500, 2500), 1: (-3142, 3142)}


def _fields_strategy(fields, text, text_max):
    kwargs = {}
    for name, lo, hi, count in fields:
        s = st.integers(lo, hi)
        kwargs[name] = s if count == 1 else st.tuples(*[s] * count)
    if text:
        kwargs[text] = st.text(alphabet=ASCII, max_size=text_max)
    return kwargs


def _set_servos(mode):
    lo, hi = SERVO_RANGES[mode]
    return st.builds(
        m.SetServos, mode=st.just(mode), targets=st.tuples(*[st.integers(lo, hi)] * 6),
        slew=st.integers(*U16),
    )


def message_strategy(cls):
    """Valid instances of one message class."""
    if cls is m.SetServos:
        return st.sampled_from([0, 1]).flatmap(_set_servos)
    for c, _size, fields, text, text_max in TABLE:
        if c is cls:
            return st.builds(cls, **_fields_strategy(fields, text, text_max))
    raise KeyError(cls)


ALL_CLASSES = [row[0] for row in TABLE] + [m.SetServos]
any_message = st.one_of([message_strategy(c) for c in ALL_CLASSES])


def test_table_covers_every_message_type():
    assert {c.MSG_TYPE for c in ALL_CLASSES} == set(m.MESSAGE_TYPES)
    assert len(ALL_CLASSES) == 14
