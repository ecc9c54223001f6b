import math

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from test_protocol_strategies import ALL_CLASSES, TABLE, any_message, message_strategy

import mobigrasp.protocol as p


@pytest.mark.parametrize("cls", ALL_CLASSES, ids=lambda c: c.__name__)
@examples(60)
@given(data=st.data())
def test_encode_decode_identity_every_message(cls, data):
    msg = data.draw(message_strategy(cls))
    seq = data.draw(st.integers(0, 255))
    assert cls.decode(msg.encode()) == msg
    wire = p.encode_message(msg, seq)
    assert wire.endswith(b"\x00") and wire.count(0) == 1 and len(wire) <= p.MAX_WIRE
    frames = p.FrameParser(known_types=p.MESSAGE_TYPES).feed(wire)
    assert len(frames) == 1
    assert frames[0].seq == seq and frames[0].msg_type == cls.MSG_TYPE
    assert frames[0].version == p.PROTOCOL_VERSION
    assert p.decode_frame(frames[0]) == msg


def test_type_codes_and_reliability_match_spec():
    expected = {
        "Hello": (0x01, True), "HelloAck": (0x02, False), "Heartbeat": (0x03, False),
        "SetServos": (0x10, True), "Gripper": (0x11, True), "SetWheels": (0x12, False),
        "Stop": (0x13, True), "Telemetry": (0x20, False), "ParamGet": (0x30, True),
        "ParamSet": (0x31, True), "ParamValue": (0x32, False), "Ack": (0x40, False),
        "Nack": (0x41, False), "Log": (0x50, False),
    }
    got = {c.__name__: (c.MSG_TYPE, c.RELIABLE) for c in p.ALL_MESSAGES}
    assert got == expected
    assert p.RELIABLE_TYPES == {0x01, 0x10, 0x11, 0x13, 0x30, 0x31}


def test_constants_match_spec():
    assert (p.NACK_OUT_OF_RANGE, p.NACK_UNKNOWN_TYPE, p.NACK_BAD_LENGTH, p.NACK_NOT_READY,
            p.NACK_BAD_PARAM, p.NACK_BAD_VERSION) == (1, 2, 3, 4, 5, 6)
    assert (p.FLAG_WATCHDOG, p.FLAG_LIMIT, p.FLAG_HANDSHAKE, p.FLAG_STOPPED, p.FLAG_RESET,
            p.FLAG_GRIPPER_CLOSED) == (1, 2, 4, 8, 16, 32)
    assert p.SONAR_NO_ECHO == 0xFFFF and p.SERVO_MODE_PULSE_US == 0 and p.SERVO_MODE_MRAD == 1


def _valid_kwargs(cls, fields, text):
    kw = {}
    for name, lo, hi, count in fields:
        v = max(lo, min(hi, 0))
        kw[name] = v if count == 1 else (v,) * count
    if text:
        kw[text] = "x"
    return kw


@pytest.mark.parametrize("row", TABLE, ids=lambda r: r[0].__name__)
def test_boundaries_accepted_and_outside_rejected_naming_field(row):
    cls, size, fields, text, _ = row
    base = _valid_kwargs(cls, fields, text)
    assert len(cls(**base).encode()) == size + (1 if text else 0)
    for name, lo, hi, count in fields:
        for ok in (lo, hi):
            kw = dict(base, **{name: ok if count == 1 else (ok,) * count})
            assert cls.decode(cls(**kw).encode()) == cls(**kw)
        for bad in (lo - 1, hi + 1):
            kw = dict(base, **{name: bad if count == 1 else (bad,) * count})
            with pytest.raises(ValueError, match=rf"{cls.__name__}\.{name}.*\[{lo}, {hi}\]"):
                cls(**kw)


@pytest.mark.parametrize("bad", [True, 1.0, math.nan, math.inf, "3", None, 2**70])
def test_non_integers_rejected(bad):
    with pytest.raises(ValueError, match="Heartbeat.time_us"):
        p.Heartbeat(time_us=bad)
    with pytest.raises(ValueError, match=r"SetWheels.right_mmps"):
        p.SetWheels(left_mmps=0, right_mmps=bad)


def test_numpy_style_integers_are_normalised():
    import numpy as np

    msg = p.SetWheels(np.int16(5), np.int64(-7))
    assert type(msg.left_mmps) is int and msg == p.SetWheels(5, -7)
    servos = p.SetServos(1, np.array([0, -1, 2, 3, 4, 5]), 0)
    assert servos.targets == (0, -1, 2, 3, 4, 5) and type(servos.targets[1]) is int


def test_set_servos_range_depends_on_mode():
    p.SetServos(0, (500, 2500, 1500, 1500, 1500, 1500), 0)
    p.SetServos(1, (-3142, 3142, 0, 0, 0, 0), 0)
    with pytest.raises(ValueError, match=r"SetServos.targets\[2\]=499.*\[500, 2500\]"):
        p.SetServos(0, (1500, 1500, 499, 1500, 1500, 1500), 0)
    with pytest.raises(ValueError, match=r"SetServos.targets\[0\]=0.*\[500, 2500\]"):
        p.SetServos(0, (0,) * 6, 0)
    with pytest.raises(ValueError, match=r"SetServos.targets\[5\]=3143"):
        p.SetServos(1, (0, 0, 0, 0, 0, 3143), 0)
    with pytest.raises(ValueError, match=r"SetServos.mode=2.*\[0, 1\]"):
        p.SetServos(2, (1500,) * 6, 0)
    with pytest.raises(ValueError, match=r"SetServos.targets must have exactly 6"):
        p.SetServos(0, (1500,) * 5, 0)
    with pytest.raises(ValueError, match=r"SetServos.targets\[1\]"):
        p.SetServos(1, (0, float("nan"), 0, 0, 0, 0), 0)


def test_text_fields_checked():
    p.Log(1, "x" * 48)
    with pytest.raises(ValueError, match="Log.text has 49 chars, at most 48"):
        p.Log(1, "x" * 49)
    with pytest.raises(ValueError, match="Hello.host_id.*printable ASCII"):
        p.Hello(1, "h\u00e9")
    with pytest.raises(ValueError, match="HelloAck.firmware_id.*printable ASCII"):
        p.HelloAck(1, "a\nb")
    with pytest.raises(ValueError, match="Log.text.*printable ASCII"):
        p.Log.decode(b"\x01\x00ab\x00c")


def test_out_of_range_on_encode_even_if_instance_was_tampered():
    msg = p.Gripper(500)
    object.__setattr__(msg, "close_permille", 1001)
    with pytest.raises(ValueError, match=r"Gripper.close_permille=1001.*\[0, 1000\]"):
        msg.encode()
    with pytest.raises(ValueError, match="Gripper.close_permille"):
        p.encode_message(msg, 0)


def test_decode_rejects_bad_length_and_values():
    with pytest.raises(p.PayloadLengthError, match="Heartbeat payload must be 4 bytes, got 3"):
        p.Heartbeat.decode(b"\x00\x00\x00")
    with pytest.raises(p.PayloadLengthError, match="Log payload must be 2..50 bytes, got 51"):
        p.Log.decode(b"\x00\x00" + b"a" * 49)
    with pytest.raises(p.FieldRangeError, match="Gripper.close_permille=1001"):
        p.Gripper.decode((1001).to_bytes(2, "little"))
    with pytest.raises(p.FieldRangeError, match="SetWheels.left_mmps=-1001"):
        p.SetWheels.decode((-1001).to_bytes(2, "little", signed=True) + b"\x00\x00")
    assert p.PayloadLengthError("x").nack_reason == p.NACK_BAD_LENGTH
    assert p.FieldRangeError("x").nack_reason == p.NACK_OUT_OF_RANGE


def test_decode_frame_unknown_type_and_bad_payload():
    with pytest.raises(p.UnknownTypeError, match="0x7F") as info:
        p.decode_frame(p.Frame(1, 0, 0x7F, b""))
    assert info.value.nack_reason == p.NACK_UNKNOWN_TYPE
    with pytest.raises(ValueError, match="Stop payload"):
        p.decode_frame(p.Frame(1, 0, 0x13, b"\x01"))


def test_frame_and_encode_message_validate():
    with pytest.raises(ValueError, match=r"Frame.seq must be an int in \[0, 255\]"):
        p.Frame(1, 256, 3, b"")
    with pytest.raises(ValueError, match="65 bytes, at most 64"):
        p.Frame(1, 0, 3, bytes(65))
    with pytest.raises(ValueError, match="Frame.seq"):
        p.encode_message(p.Stop(), -1)
    with pytest.raises(TypeError):
        p.encode_message("not a message", 0)


def test_little_endian_layouts():
    assert p.Heartbeat(0x01020304).encode() == b"\x04\x03\x02\x01"
    assert p.SetWheels(-2, 258).encode() == b"\xfe\xff\x02\x01"
    assert p.ParamSet(0x0102, -1).encode() == b"\x02\x01\xff\xff\xff\xff"
    assert p.Hello(1, "ab", 0x0203).encode() == b"\x01\x03\x02ab"
    tel = p.Telemetry(1, -1, 2, (1500,) * 6, (0xFFFF,) * 5, 0x21, 3, 4, 5, 6)
    enc = tel.encode()
    assert enc[:12] == b"\x01\x00\x00\x00\xff\xff\xff\xff\x02\x00\x00\x00"
    assert enc[12:24] == (1500).to_bytes(2, "little") * 6
    assert enc[24:34] == b"\xff" * 10
    assert enc[34:] == bytes([0x21, 0, 3, 0, 4, 0, 5, 0, 6, 0])


@examples(50)
@given(any_message, st.integers(0, 255))
def test_wire_bytes_are_deterministic_and_bounded(msg, seq):
    a = p.encode_message(msg, seq)
    assert a == p.encode_message(msg, seq)
    assert len(a) == len(msg.encode()) + 7  # COBS code + 3 header + 2 CRC + delimiter
