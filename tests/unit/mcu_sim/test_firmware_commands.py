"""Firmware command handling, in process: ACK/NACK, duplicates, PARAMs, servo modes, slew, STOP,
gripper, reset, determinism."""

import math
import struct

import pytest

from mobigrasp.mcu_sim.firmware.params import P_TELEMETRY_HZ, P_WATCHDOG_MS, param_id
from mobigrasp.mcu_sim.firmware.servo_table import mrad_to_us
from mobigrasp.mcu_sim.mcu import Mcu, McuConfig
from mobigrasp.mcu_sim.mcu_host import InProcessHost
from mobigrasp.protocol import (
    FLAG_GRIPPER_CLOSED,
    FLAG_LIMIT,
    FLAG_RESET,
    FLAG_STOPPED,
    FLAG_WATCHDOG,
    NACK_BAD_LENGTH,
    NACK_BAD_PARAM,
    NACK_NOT_READY,
    NACK_OUT_OF_RANGE,
    NACK_SEQ_REUSED,
    NACK_UNKNOWN_TYPE,
    PROTOCOL_VERSION,
    Ack,
    Frame,
    Gripper,
    Heartbeat,
    Hello,
    Nack,
    ParamGet,
    ParamSet,
    ParamValue,
    SetServos,
    SetWheels,
    Stop,
    encode_frame,
)

pytestmark = [pytest.mark.both_mcus, pytest.mark.simavr]


def ready(config=None):
    mcu = Mcu(config)
    host = InProcessHost(mcu)
    host.send(Hello(PROTOCOL_VERSION, "t", 0), seq=0)
    host.run_ms(12)
    assert Ack(0) in host.messages()
    host.clear()
    return mcu, host


def pulses(mcu):
    return tuple(mcu.servo_pulse_us(ch) for ch in range(6))


def test_duplicate_seq_is_acked_again_but_not_executed_twice():
    mcu, host = ready()
    first = SetServos(0, (1500, 1600, 1500, 1500, 1500, 1500), 0)
    host.send(first, seq=5)
    host.run_ms(45)
    host.send(SetServos(0, (1500, 1500, 1500, 1500, 1500, 1500), 0), seq=6)
    host.run_ms(45)
    host.send(first, seq=5)  # a late copy: answered again, not executed again
    host.run_ms(45)
    assert host.messages(Ack).count(Ack(5)) == 2
    assert pulses(mcu)[1] == 1500.0
    assert mcu.stats()["duplicates"] == 1
    # A new HELLO starts a new session: seq 5 is new again.
    host.send(Hello(PROTOCOL_VERSION, "t2", 0), seq=0)
    host.send(first, seq=5)
    host.run_ms(45)
    assert pulses(mcu)[1] == 1600.0


def test_seq_reused_with_other_content_is_nacked_not_dropped():
    mcu, host = ready()
    host.send(SetServos(0, (1500, 1600, 1500, 1500, 1500, 1500), 0), seq=5)
    host.run_ms(45)
    host.send(SetServos(0, (1500, 1900, 1500, 1500, 1500, 1500), 0), seq=5)  # same seq
    host.run_ms(45)
    assert host.messages(Ack).count(Ack(5)) == 1
    assert Nack(5, NACK_SEQ_REUSED) in host.messages()
    assert pulses(mcu)[1] == 1600.0


def test_seq_reused_after_the_wrap_is_a_new_command():
    # Sequence numbers wrap every 256 frames of the sender (a few seconds of 50 Hz traffic): a
    # reliable command that reuses the seq of one a whole lap of frames ago must run.
    mcu, host = ready()
    host.send(SetServos(0, (1500, 1600, 1500, 1500, 1500, 1500), 0), seq=7)
    host.run_ms(45)
    for k in range(8, 7 + 256):
        host.send(Heartbeat(k), seq=k & 0xFF)
        host.run_ms(2)
    host.send(SetServos(0, (1500, 1900, 1500, 1500, 1500, 1500), 0), seq=7)
    host.run_ms(45)
    assert pulses(mcu)[1] == 1900.0
    assert mcu.stats()["duplicates"] == 0


def frame(msg_type, payload, seq):
    return encode_frame(Frame(PROTOCOL_VERSION, seq, msg_type, payload))


@pytest.mark.parametrize(("wire", "reason"), [
    (frame(0x77, b"\x01\x02", 31), NACK_UNKNOWN_TYPE),
    (frame(SetServos.MSG_TYPE, b"\x00\x01", 31), NACK_BAD_LENGTH),
    (frame(SetServos.MSG_TYPE, struct.pack("<B6hH", 0, 3000, 1500, 1500, 1500, 1500, 1500, 0),
           31), NACK_OUT_OF_RANGE),
    (frame(ParamGet.MSG_TYPE, struct.pack("<H", 999), 31), NACK_BAD_PARAM),
    (frame(ParamSet.MSG_TYPE, struct.pack("<Hi", P_WATCHDOG_MS, -5), 31), NACK_BAD_PARAM),
    (frame(ParamSet.MSG_TYPE, struct.pack("<Hi", P_TELEMETRY_HZ, 101), 31), NACK_OUT_OF_RANGE),
    (frame(ParamSet.MSG_TYPE, struct.pack("<Hi", 100, 2), 31), NACK_BAD_PARAM),  # read-only
])
def test_bad_commands_are_nacked_with_their_reason_and_do_not_actuate(wire, reason):
    mcu, host = ready()
    host.run_ms(45)
    before = pulses(mcu)
    host.send_raw(wire)
    host.run_ms(45)
    assert Nack(31, reason) in host.messages(Nack)
    assert pulses(mcu) == before


def test_commands_before_hello_are_refused():
    mcu = Mcu()
    host = InProcessHost(mcu)
    host.send(Gripper(1000), seq=3)
    host.send(SetWheels(300, 300), seq=4)
    host.run_ms(60)
    assert Nack(3, NACK_NOT_READY) in host.messages()
    assert pulses(mcu)[0] == 1000.0 and mcu.wheel_duty() == (0, 0)
    assert mcu.stats()["not_ready"] == 2


def test_param_get_set_and_their_effect(mcu_backend):
    mcu, host = ready()
    host.send(ParamGet(param_id("watchdog_ms")), seq=1)
    host.send(ParamSet(P_TELEMETRY_HZ, 10), seq=2)
    host.send(ParamSet(P_WATCHDOG_MS, 100), seq=3)
    host.run_ms(10)
    values = host.messages(ParamValue)
    assert ParamValue(P_WATCHDOG_MS, 250) in values
    assert ParamValue(P_TELEMETRY_HZ, 10) in values
    assert ParamValue(P_WATCHDOG_MS, 100) in values
    host.clear()
    host.run_ms(1000)
    assert 9 <= len(host.telemetry()) <= 11  # 10 Hz now
    trip = [t for t, m in host.received if getattr(m, "flags", 0) & FLAG_WATCHDOG]
    assert trip and mcu.stats()["watchdog_trips"] == 1


def test_mrad_mode_follows_the_conventions_servo_law():
    mcu, host = ready()
    angles = (600, 1000, -1571, -1200, 1571, -700)
    host.send(SetServos(1, angles, 0), seq=1)
    host.run_ms(45)
    for ch in range(1, 6):
        pulse0 = (1500, 2455, 2455, 545, 1500)[ch - 1]
        ref = pulse0 + angles[ch] / 1000 * 2000 / math.pi
        assert abs(mrad_to_us(ch, angles[ch]) - ref) <= 0.5
        assert abs(pulses(mcu)[ch] - ref) <= 1.0
    assert pulses(mcu)[0] == 1600.0  # channel 0 in mrad mode is the gripper in per mille


def test_clamping_counts_a_limit_hit_and_flags_one_telemetry():
    mcu, host = ready()
    host.send(SetServos(0, (1000, 1500, 1500, 1500, 1500, 2500), 0), seq=1)
    host.run_ms(45)
    assert pulses(mcu)[5] == 2391.0  # waist limit 1.4 rad
    tel = host.telemetry()
    assert mcu.limit_hits() == 1 and tel[-1].limit_hits == 1
    assert sum(1 for t in tel if t.flags & FLAG_LIMIT) == 1


@pytest.mark.not_on("simavr", "reads each period's width through the Python model's "
                    "subscribe_servo")
def test_slew_limits_the_change_per_period():
    mcu, host = ready()
    seen = []
    mcu.subscribe_servo(1, lambda t, w: seen.append(w))
    host.send(SetServos(0, (1000, 2000, 1500, 1500, 1500, 1500), 500), seq=1)
    for _ in range(12):  # heartbeats keep the watchdog (250 ms) from holding the arm
        host.run_ms(100)
        host.send(Heartbeat(0))
    steps = {b - a for a, b in zip(seen, seen[1:], strict=False)}
    assert steps <= {0, 10_000}  # 500 µs/s = 10 µs per 20 ms period
    assert seen[-1] == 2_000_000
    ramp = [w for w in seen if 1_500_000 < w < 2_000_000]
    assert len(ramp) == 49


def test_stop_halts_wheels_and_holds_the_arm_mid_slew():
    mcu, host = ready()
    host.send(SetWheels(300, 300))
    host.send(SetServos(0, (1000, 2000, 1500, 1500, 1500, 1500), 500), seq=1)
    host.run_ms(200)
    assert mcu.wheel_duty()[0] > 0
    host.send(Stop(), seq=2)
    host.run_ms(3)
    assert mcu.wheel_duty() == (0, 0)
    host.run_ms(40)
    held = pulses(mcu)[1]
    host.run_ms(200)
    assert pulses(mcu)[1] == held < 2000.0
    assert host.telemetry()[-1].flags & FLAG_STOPPED


def test_gripper_and_its_flag():
    mcu, host = ready()
    host.send(Gripper(1000), seq=1)
    host.run_ms(45)
    assert pulses(mcu)[0] == 2000.0
    assert host.telemetry()[-1].flags & FLAG_GRIPPER_CLOSED


def test_reset_reinitialises_and_flags_the_first_telemetry():
    mcu, host = ready()
    host.send(Gripper(1000), seq=1)
    host.run_ms(45)
    host.clear()
    mcu.reset()
    host.run_ms(45)
    tel = host.telemetry()
    assert tel[0].flags & FLAG_RESET and not tel[1].flags & FLAG_RESET
    assert pulses(mcu)[0] == 1000.0
    host.send(Gripper(1000), seq=2)
    host.run_ms(10)
    assert Nack(2, NACK_NOT_READY) in host.messages()


def test_heartbeat_feeds_the_watchdog():
    mcu, host = ready()
    host.send(SetWheels(200, 200))
    for _ in range(10):
        host.run_ms(100)
        host.send(Heartbeat(mcu.now_us))
    assert mcu.stats()["watchdog_trips"] == 0 and mcu.wheel_duty()[0] > 0


def test_same_inputs_give_the_same_bytes():
    def run():
        mcu, host = ready(McuConfig(params={"telemetry_hz": 25}))
        host.send(SetServos(0, (1200, 1700, 1500, 1500, 1500, 1500), 300), seq=1)
        host.send(SetWheels(150, -150))
        mcu.set_encoder_ticks(300, -200, mcu.now_us + 500_000)
        host.run_ms(700)
        return host.received

    assert run() == run()


def test_param_command_reusing_the_hello_seq_is_refused_without_a_value():
    # HELLO seq 0 is remembered with its CRC; a PARAM_SET of an unknown id with the same seq is
    # another command reusing a recent seq: NACK_SEQ_REUSED, not executed, no PARAM_VALUE
    mcu, host = ready()
    host.send(ParamSet(0x6500, 0), seq=0)
    host.run_ms(12)
    msgs = host.messages()
    assert Nack(0, NACK_SEQ_REUSED) in msgs and Ack(0) not in msgs
    assert not any(isinstance(m, ParamValue) for m in msgs)
    assert mcu.stats()["duplicates"] == 0
