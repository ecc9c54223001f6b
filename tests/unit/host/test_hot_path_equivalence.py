"""The host's hot-path shortcuts (perf round 4) give exactly what the full checks give.

Each shortcut skips a check that holds by construction for the usual values; these tests feed
both usual and unusual values and compare with the general path the shortcut stands in for.
"""

from __future__ import annotations

import random

import pytest

from mobigrasp.host import arm_calib
from mobigrasp.host.outgoing_guard import OutgoingRejected, check_int, check_servo_mrad, coerce_int
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.cobs import cobs_decode, cobs_encode
from mobigrasp.protocol.frame import PROTOCOL_VERSION, Frame, FrameParser, encode_frame
from mobigrasp.protocol.reliable import RetransmitQueue


def _cobs_reference(data: bytes) -> bytes:
    out = bytearray()
    for block in bytes(data).split(b"\x00"):
        while len(block) >= 254:
            out.append(0xFF)
            out += block[:254]
            block = block[254:]
        out.append(len(block) + 1)
        out += block
    return bytes(out)


def test_cobs_encode_matches_the_reference_and_round_trips():
    rng = random.Random(4)
    cases = [b"", b"\x00", b"\x00\x00", b"\x01" * 253, b"\x01" * 254, b"\x01" * 600,
             b"\x00" + b"\x02" * 300 + b"\x00"]
    cases += [bytes(rng.choice((0, 0, 1, 7, 255)) for _ in range(rng.randrange(0, 700)))
              for _ in range(200)]
    for data in cases:
        enc = cobs_encode(data)
        assert enc == _cobs_reference(data)
        assert cobs_decode(enc) == data


def _all_sample_messages() -> list[m.Message]:
    return [
        m.Hello(PROTOCOL_VERSION, "host", 3), m.HelloAck(1, "fw-1.0", 0), m.Heartbeat(0xFFFFFFFF),
        m.SetServos(m.SERVO_MODE_MRAD, (0, -1571, -3000, -2800, 3000, 1400), 7),
        m.SetServos(m.SERVO_MODE_PULSE_US, (500, 1500, 2500, 1000, 2000, 1500)),
        m.Gripper(1000), m.SetWheels(-1000, 1000), m.Stop(),
        m.Telemetry(123456, -5, 2**31 - 1, (500, 2500, 1500, 1000, 2000, 1700),
                    (0, 1, 0xFFFF, 300, 4000), 0xFFFF, 1, 2, 3, 4),
        m.ParamGet(2), m.ParamSet(2, -7), m.ParamValue(2, 2**31 - 1), m.Ack(255), m.Nack(0, 9),
        m.Log(3, "ok"),
    ]


@pytest.mark.parametrize("seq", [0, 1, 254, 255])
def test_encode_message_equals_the_frame_path(seq):
    for msg in _all_sample_messages():
        via_frame = encode_frame(Frame(PROTOCOL_VERSION, seq, msg.MSG_TYPE, msg.encode()))
        assert m.encode_message(msg, seq) == via_frame


@pytest.mark.parametrize("seq", [-1, 256, True, 1.0, None])
def test_encode_message_still_rejects_a_bad_seq(seq):
    with pytest.raises(ValueError, match="Frame.seq"):
        m.encode_message(m.Heartbeat(1), seq)


def test_encode_message_still_rejects_a_non_message():
    with pytest.raises(TypeError):
        m.encode_message(Frame(1, 0, 3, b""), 0)


def test_trusted_decode_is_the_constructed_message():
    trusted = {cls for cls in m.ALL_MESSAGES if cls._TRUSTED_DECODE}
    # the types whose every field takes its whole struct range, without text
    assert trusted == {m.Heartbeat, m.Stop, m.Telemetry, m.ParamGet, m.ParamSet,
                       m.ParamValue, m.Ack, m.Nack}
    rng = random.Random(8)
    for cls in trusted:
        for _ in range(50):
            payload = bytes(rng.randrange(256) for _ in range(cls._STRUCT.size))
            got = cls.decode(payload)
            raw = cls._STRUCT.unpack(payload)
            kwargs, i = {}, 0
            for f in cls._SPEC:
                kwargs[f.name] = raw[i] if f.count == 1 else tuple(raw[i:i + f.count])
                i += f.count
            want = cls(**kwargs)
            assert got == want and vars(got) == vars(want)
            assert all(type(v) in (int, tuple) for v in vars(got).values())
            assert got.encode() == payload
    with pytest.raises(m.PayloadLengthError):
        m.Telemetry.decode(bytes(43))


def test_untrusted_decode_still_checks_ranges():
    with pytest.raises(m.FieldRangeError, match="Gripper.close_permille"):
        m.Gripper.decode((1001).to_bytes(2, "little"))
    with pytest.raises(m.FieldRangeError, match="SetServos.targets"):
        m.SetServos.decode(bytes([0]) + (400).to_bytes(2, "little") * 6 + bytes(2))


@pytest.mark.parametrize(("bad", "bad_target"), [(True, True), (1.0, 1.0), (2**40, 3143),
                                                 (-1, -3143)])
def test_construction_and_tampered_encode_still_check_every_field(bad, bad_target):
    with pytest.raises(m.FieldRangeError, match="Heartbeat.time_us"):
        m.Heartbeat(bad)
    msg = m.SetServos(m.SERVO_MODE_MRAD, (0, 0, 0, 0, 0, 0))
    object.__setattr__(msg, "targets", (0, 0, bad_target, 0, 0, 0))
    with pytest.raises(m.FieldRangeError, match=r"SetServos.targets\[2\]"):
        msg.encode()


def test_construction_still_normalises_what_the_full_check_accepts():
    class Int(int):
        pass

    msg = m.SetServos(m.SERVO_MODE_MRAD, [0, 1, -2, Int(-3), 4, 5], slew=Int(9))
    assert msg.targets == (0, 1, -2, -3, 4, 5) and type(msg.targets) is tuple
    assert type(msg.targets[3]) is int and type(msg.slew) is int
    # mode decides the targets' range (SetServos._range), also on the short path
    with pytest.raises(m.FieldRangeError):
        m.SetServos(m.SERVO_MODE_PULSE_US, (0, 1500, 1500, 1500, 1500, 1500))


def test_telemetry_through_the_parser_equals_the_constructed_message():
    tel = _all_sample_messages()[8]
    parser = FrameParser()
    frames = parser.feed(m.encode_message(tel, 9) * 2)
    assert [m.decode_frame(f) for f in frames] == [tel, tel]


def test_guard_short_paths_agree_with_the_full_checks():
    assert check_int("x", 5, 0, 10) == 5
    for bad in (True, 11, -1, 5.0, float("nan"), None, "5"):
        with pytest.raises(OutgoingRejected):
            check_int("x", bad, 0, 10)
    assert coerce_int("x", 7) == 7 and coerce_int("x", 2.6) == 3
    with pytest.raises(OutgoingRejected):
        coerce_int("x", 1 << 63)
    with pytest.raises(OutgoingRejected):
        coerce_int("x", False)
    ok = [500, -1571, -3000, 0, 3000, 1400]
    assert check_servo_mrad(ok) == tuple(ok) and check_servo_mrad(tuple(ok)) == tuple(ok)
    for i, bad in ((0, 1001), (2, 1), (4, True), (5, 3.0)):
        targets = list(ok)
        targets[i] = bad
        with pytest.raises(OutgoingRejected, match=arm_calib.JOINT_NAMES[i]):
            check_servo_mrad(targets)
    # a mapping of six channels is indexed, not iterated (its keys are not the targets)
    as_map = {ch: v for ch, v in enumerate(ok)}
    assert check_servo_mrad(as_map) == tuple(ok)


def test_retransmit_queue_membership():
    q = RetransmitQueue()
    q.track(4, b"x", 0)
    assert 4 in q and 5 not in q and q.in_flight() == [4]
    q.ack(4)
    assert 4 not in q


def test_clamp_joints_short_path_equals_clamp_mrad():
    import numpy as np

    rng = random.Random(2)
    for _ in range(300):
        angles = [rng.randrange(-4000, 4000) for _ in range(6)]
        want = tuple(arm_calib.clamp_mrad(ch, a) for ch, a in enumerate(angles))
        assert arm_calib.clamp_joints_mrad(angles) == want
        assert arm_calib.clamp_joints_mrad(tuple(angles)) == want
    with pytest.raises(ValueError, match="angle_mrad must be an int"):
        arm_calib.clamp_joints_mrad([0, 0, 0, 0, 0, np.int64(5)])
    with pytest.raises(ValueError, match="need 6"):
        arm_calib.clamp_joints_mrad([0] * 5)


def test_task_clean_keeps_clean_inputs_and_cleans_the_others():
    from dataclasses import replace

    from mobigrasp.host.task import Task, TaskInputs

    task = Task("000")
    clean = TaskInputs(joints_mrad=(0, 1, -2, -3, 4, 5), x_mm=10, y_mm=-20, heading_mrad=30,
                       v_mmps=4, sonar_mm=(1, 2), detections={"a": 1})
    got, dets = task._clean(clean)
    assert got is clean and dets is clean.detections and task.last_pose == (10, -20, 30, 4)
    assert task.counters["bad_inputs"] == 0

    class Int(int):
        pass

    odd = replace(clean, joints_mrad=[0, 1, -2, -3, 4, Int(5)], x_mm=True, v_mmps=Int(7))
    got, dets = task._clean(odd)
    assert got == replace(clean, x_mm=1, v_mmps=7) and type(got.joints_mrad) is tuple
    assert all(type(v) is int for v in (*got.joints_mrad, got.x_mm, got.v_mmps))
    assert task.last_pose == (1, -20, 30, 7) and task.counters["bad_inputs"] == 0
    got, dets = task._clean(replace(clean, joints_mrad=(1, 2), detections=None))
    assert got.joints_mrad is None and dets == {} and task.counters["bad_inputs"] == 2


def test_posture_params_follow_the_task_params():
    from dataclasses import replace

    from mobigrasp.host.task import Task

    task = Task("000")
    pp = task.posture_params()
    assert pp.max_step_mrad == task.p.posture_step_mrad and task.posture_params() is pp
    assert task.posture_params(7).max_step_mrad == 7
    task.p = replace(task.p, posture_step_mrad=5, posture={"margin_mode": "limits"})
    pp2 = task.posture_params()
    assert (pp2.max_step_mrad, pp2.margin_mode) == (5, "limits")


def test_servo_checks_follow_the_mode():
    pulses = (500, 1500, 2500, 1000, 2000, 1500)
    assert m.SetServos(m.SERVO_MODE_PULSE_US, pulses).encode()[0] == m.SERVO_MODE_PULSE_US
    assert m.SetServos(m.SERVO_MODE_MRAD, pulses).targets == pulses  # as mrad: in range
    with pytest.raises(m.FieldRangeError, match=r"SetServos.targets\[1\]=3143"):
        m.SetServos(m.SERVO_MODE_MRAD, (0, 3143, 0, 0, 0, 0))
    with pytest.raises(m.FieldRangeError, match=r"SetServos.targets\[0\]=0"):
        m.SetServos(m.SERVO_MODE_PULSE_US, (0, 1500, 1500, 1500, 1500, 1500))
    msg = m.SetServos(m.SERVO_MODE_MRAD, (0, 1, 2, 3, 4, 5))
    object.__setattr__(msg, "mode", m.SERVO_MODE_PULSE_US)  # now the targets are too small
    with pytest.raises(m.FieldRangeError, match=r"SetServos.targets\[0\]=0"):
        msg.encode()
    object.__setattr__(msg, "mode", 2)
    with pytest.raises(m.FieldRangeError, match="SetServos.mode=2"):
        msg.encode()


def test_parser_buffers_pieces_as_the_general_path_does():
    tel = _all_sample_messages()[8]
    wire = m.encode_message(tel, 1) + m.encode_message(m.Heartbeat(5), 2)
    for cut in range(1, len(wire)):
        for step in (1, 3, 29):
            parser = FrameParser()
            got = parser.feed(wire[:cut])
            for i in range(cut, len(wire), step):
                got += parser.feed(wire[i:i + step])
            assert [m.decode_frame(f) for f in got] == [tel, m.Heartbeat(5)]
            assert parser.pending == 0 and parser.stats.bytes_in == len(wire)
    parser = FrameParser()
    assert parser.feed(b"\x01" * 60) == [] and parser.feed(b"\x01" * 60) == []  # oversize
    assert parser.stats.oversize == 1 and parser.feed(b"\x02\x00" + wire)[0].seq == 1


def test_joint_angle_cache_gives_what_the_conversion_gives():
    pulses = (1000, 1500, 2455, 1800, 545, 1234)
    want = tuple(arm_calib.pulse_us_to_mrad(ch, p) for ch, p in enumerate(pulses))
    assert arm_calib.pulses_to_joints_mrad(pulses) == want  # computed (and remembered)
    assert arm_calib.pulses_to_joints_mrad(pulses) == want  # remembered
    assert arm_calib.pulses_to_joints_mrad(tuple(float(p) for p in pulses)) == want
    assert arm_calib.pulses_to_joints_mrad(list(pulses)) == want
    with pytest.raises(TypeError):
        arm_calib.pulses_to_joints_mrad((1000, 1500, 2455, 1800, 545, [1234]))
    with pytest.raises(ValueError, match="pulse 2600"):
        arm_calib.pulses_to_joints_mrad((1000, 1500, 2455, 1800, 545, 2600))
    with pytest.raises(ValueError, match="pulse 2600"):  # refused again: never remembered
        arm_calib.pulses_to_joints_mrad((1000, 1500, 2455, 1800, 545, 2600))
    rng = random.Random(3)
    for _ in range(3000):  # new combinations of (partly) remembered channel pulses
        pulses = tuple(rng.randrange(500, 2501) for _ in range(6))
        want = tuple(arm_calib.pulse_us_to_mrad(ch, p) for ch, p in enumerate(pulses))
        assert arm_calib.pulses_to_joints_mrad(pulses) == want


def test_div_round_short_paths_round_halves_away_from_zero():
    from mobigrasp.host.fixedpoint import div_round

    def reference(num: int, den: int) -> int:
        q, r = divmod(abs(num), abs(den))
        if 2 * r >= abs(den):
            q += 1
        return q if (num >= 0) == (den > 0) else -q

    rng = random.Random(5)
    cases = [(n, d) for n in range(-25, 26) for d in (1, 2, 3, 4, 5, 10)]
    cases += [(rng.randrange(-10**9, 10**9), rng.randrange(1, 10**6)) for _ in range(2000)]
    for n, d in cases:
        assert div_round(n, d) == reference(n, d)
        assert div_round(n, -d) == reference(n, -d)
    assert (div_round(-5, 2), div_round(5, 2), div_round(-7, 2)) == (-3, 3, -4)
    with pytest.raises(ValueError):
        div_round(1, 0)


def test_isqrt_equals_the_digit_by_digit_root_of_the_board():
    from mobigrasp.host.fixedpoint import isqrt, isqrt_digits

    rng = random.Random(6)
    values = list(range(0, 5000)) + [2**k + d for k in range(1, 80) for d in (-1, 0, 1)]
    values += [rng.randrange(0, 2**64) for _ in range(3000)] + [7.9, 1e6]
    for n in values:
        assert isqrt(n) == isqrt_digits(n)
    with pytest.raises(ValueError, match="negative"):
        isqrt(-1)


def test_a_message_type_that_cannot_fit_a_frame_is_refused_when_defined():
    from dataclasses import dataclass
    from typing import ClassVar

    with pytest.raises(TypeError, match="exceed 64 bytes"):
        @dataclass(frozen=True)
        class TooBig(m.Message):
            MSG_TYPE: ClassVar[int] = 0x7F
            _SPEC: ClassVar = (m._f("values", "I", count=17),)
            values: tuple
