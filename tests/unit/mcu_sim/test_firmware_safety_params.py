"""Safety PARAMs cannot be talked away over the wire (docs/firmware.md "Safety limits"): the
mechanical servo limits only narrow, the watchdog stays in 50..1000 ms, a HELLO restores them,
and no sequence of messages moves a pulse past the limits or keeps the wheels running after the
host goes silent."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.mcu_sim.firmware.params import P_SERVO_MAX_BASE, P_SERVO_MIN_BASE, P_WATCHDOG_MS
from mobigrasp.mcu_sim.mcu import Mcu, McuConfig
from mobigrasp.mcu_sim.mcu_host import InProcessHost
from mobigrasp.protocol import (
    PROTOCOL_VERSION,
    Ack,
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
    encode_message,
)
from mobigrasp.protocol.joints import MECH_LIMITS_US
from mobigrasp.protocol.messages import NACK_BAD_PARAM

CONTROL_PERIOD_US = 10_000

pytestmark = [pytest.mark.both_mcus, pytest.mark.simavr]


def _session():
    mcu = Mcu()
    host = InProcessHost(mcu)
    host.send(Hello(PROTOCOL_VERSION, "t", 0))
    host.run_ms(5)
    return mcu, host


def _answer(host, seq):
    for m in host.messages():
        if isinstance(m, Ack | Nack) and m.acked_seq == seq:
            return m
    raise AssertionError(f"no answer to seq {seq}")


def _param(host, pid):
    """The value the firmware reports for ``pid`` (PARAM_GET over the wire)."""
    host.clear()
    host.send(ParamGet(pid))
    for _ in range(60):  # the AVR may still be busy with a PARAM_SET or a HELLO (~15 ms each)
        host.run_ms(1)
        values = [m.value for m in host.messages(ParamValue) if m.param_id == pid]
        if values:
            return values[-1]
    raise AssertionError(f"no PARAM_VALUE for {pid} within 60 ms")


@pytest.mark.parametrize("value", [0, 49, 1001, 10_000, -5])
def test_watchdog_outside_50_to_1000_ms_is_refused_bad_param(value):
    mcu, host = _session()
    seq = host.send(ParamSet(P_WATCHDOG_MS, value))
    host.run_ms(5)
    assert _answer(host, seq) == Nack(seq, NACK_BAD_PARAM)
    assert _param(host, P_WATCHDOG_MS) == 250


def test_watchdog_zero_cannot_keep_the_wheels_running_through_host_silence():
    mcu, host = _session()
    host.send(ParamSet(P_WATCHDOG_MS, 0))
    host.send(SetWheels(500, 500))
    host.run_ms(100)
    assert mcu.wheel_duty() != (0, 0)
    host.run_ms(250)  # 250 ms default watchdog after the last frame, plus margin
    assert mcu.wheel_duty() == (0, 0)
    assert mcu.stats()["watchdog_trips"] == 1


def test_watchdog_limits_are_accepted(mcu_backend):
    for value in (50, 1000):
        mcu, host = _session()
        seq = host.send(ParamSet(P_WATCHDOG_MS, value))
        host.run_ms(5)
        assert _answer(host, seq) == Ack(seq)
        assert ParamValue(P_WATCHDOG_MS, value) in host.messages()


@pytest.mark.parametrize("ch", range(6))
def test_servo_limit_params_cannot_widen_the_mechanical_limits(ch):
    mcu, host = _session()
    lo, hi = MECH_LIMITS_US[ch]
    s_min = host.send(ParamSet(P_SERVO_MIN_BASE + ch, lo - 1))
    s_max = host.send(ParamSet(P_SERVO_MAX_BASE + ch, hi + 1))
    host.run_ms(10)
    assert _answer(host, s_min) == Nack(s_min, NACK_BAD_PARAM)
    assert _answer(host, s_max) == Nack(s_max, NACK_BAD_PARAM)
    # then command both ends in microseconds: the servo stops at the mechanical limits
    host.send(SetServos(0, (500,) * 6, 0))
    host.run_ms(45)
    assert mcu.servo_pulse_us(ch) == lo
    host.send(SetServos(0, (2500,) * 6, 0))
    host.run_ms(45)
    assert mcu.servo_pulse_us(ch) == hi


def test_servo_limit_params_may_narrow():
    mcu, host = _session()
    seq = host.send(ParamSet(P_SERVO_MAX_BASE + 2, 2000))
    host.send(SetServos(0, (2500,) * 6, 0))
    host.run_ms(45)
    assert _answer(host, seq) == Ack(seq)
    assert mcu.servo_pulse_us(2) == 2000


def test_build_time_overrides_pass_the_same_checks():
    with pytest.raises(ValueError, match="refused"):
        Mcu(McuConfig(params={"watchdog_ms": 0}))
    with pytest.raises(ValueError, match="refused"):
        Mcu(McuConfig(params={"servo2_min_us": 500}))
    mcu = Mcu(McuConfig(params={"watchdog_ms": 500}))
    host = InProcessHost(mcu)
    host.send(Hello(PROTOCOL_VERSION, "t", 0))
    host.run_ms(5)
    assert _param(host, P_WATCHDOG_MS) == 500


def test_hello_restores_every_safety_param_to_its_power_on_value(mcu_backend):
    mcu = Mcu(McuConfig(params={"watchdog_ms": 400}))
    host = InProcessHost(mcu)
    host.send(Hello(PROTOCOL_VERSION, "t", 0))
    host.run_ms(5)
    host.send(ParamSet(P_WATCHDOG_MS, 1000))
    host.send(ParamSet(5, 100))  # wheel_max_mmps
    host.send(ParamSet(P_SERVO_MAX_BASE + 2, 1500))
    host.send(ParamSet(2, 10))  # telemetry_hz: not a safety PARAM, kept
    host.run_ms(20)
    assert (_param(host, P_WATCHDOG_MS), _param(host, 5),
            _param(host, P_SERVO_MAX_BASE + 2)) == (1000, 100, 1500)
    host.send(Hello(PROTOCOL_VERSION, "t2", 0))
    host.run_ms(5)
    assert _param(host, P_WATCHDOG_MS) == 400
    assert _param(host, 5) == 800
    assert _param(host, P_SERVO_MAX_BASE + 2) == MECH_LIMITS_US[2][1]
    if mcu_backend != "simavr":  # the ELF's servo table is not read off the core
        assert mcu.firmware.servos.max_us[2] == MECH_LIMITS_US[2][1]
    assert _param(host, 2) == 10
    # and the restored watchdog is the one in force: silence trips it after 400 ms
    host.send(SetWheels(300, 300))
    host.run_ms(390)
    assert mcu.wheel_duty() != (0, 0)
    host.run_ms(25)
    assert mcu.wheel_duty() == (0, 0)


# -- property: no message sequence gets past the limits ------------------------------------------
seqs = st.integers(0, 255)
messages = st.one_of(
    st.builds(lambda v: ParamSet(P_WATCHDOG_MS, v),
              st.one_of(st.integers(-2**31, 2**31 - 1), st.sampled_from([0, 49, 50, 1000, 1001]))),
    st.builds(lambda ch, v: ParamSet(P_SERVO_MIN_BASE + ch, v), st.integers(0, 5),
              st.integers(400, 2600)),
    st.builds(lambda ch, v: ParamSet(P_SERVO_MAX_BASE + ch, v), st.integers(0, 5),
              st.integers(400, 2600)),
    st.builds(ParamSet, st.integers(0, 0xFFFF), st.integers(-2**31, 2**31 - 1)),
    st.builds(ParamGet, st.integers(0, 0xFFFF)),
    st.builds(lambda t, s: SetServos(0, tuple(t), s),
              st.lists(st.integers(500, 2500), min_size=6, max_size=6), st.integers(0, 4000)),
    st.builds(lambda t, s: SetServos(1, tuple(t), s),
              st.lists(st.integers(-3142, 3142), min_size=6, max_size=6), st.integers(0, 4000)),
    st.builds(Gripper, st.integers(0, 1000)),
    st.builds(SetWheels, st.integers(-1000, 1000), st.integers(-1000, 1000)),
    st.just(Stop()),
    st.builds(Heartbeat, st.integers(0, 2**32 - 1)),
    st.just(Hello(PROTOCOL_VERSION, "p", 0)),
)
steps = st.tuples(st.one_of(messages, st.binary(min_size=1, max_size=40)), seqs,
                  st.one_of(st.integers(1, 30), st.integers(200, 1100)))


@pytest.mark.not_on("simavr", "reads the Python firmware's PARAM and servo tables every "
                    "millisecond")
@examples(40)
@given(st.lists(steps, min_size=1, max_size=10))
def test_no_message_sequence_passes_the_mechanical_limits_or_the_watchdog(plan):
    mcu, host = _session()
    fw = mcu.firmware
    widths = {ch: [] for ch in range(6)}
    for ch in range(6):
        mcu.subscribe_servo(ch, lambda t, w, ch=ch: widths[ch].append(w))
    byte_us = math.ceil(10e6 / mcu.baud)
    line_free_us = mcu.now_us
    moving_late = []
    for item, seq, wait_ms in plan + [(Heartbeat(0), 0, 1200)]:
        wire = item if isinstance(item, bytes) else encode_message(item, seq)
        host.send_raw(wire)
        # the frame's last byte is in the MCU by then (frames queue on the line)
        line_free_us = max(line_free_us, mcu.now_us) + len(wire) * byte_us
        for _ in range(wait_ms):
            host.run_ms(1)
            wd_ms = fw.params.get(P_WATCHDOG_MS)
            assert 50 <= wd_ms <= 1000
            if mcu.now_us > line_free_us + wd_ms * 1000 + CONTROL_PERIOD_US:
                if mcu.wheel_duty() != (0, 0):
                    moving_late.append(mcu.now_us - line_free_us)
    assert not moving_late, moving_late[:3]
    for ch in range(6):
        lo, hi = MECH_LIMITS_US[ch]
        assert widths[ch]
        assert all(lo * 1000 <= w <= hi * 1000 for w in widths[ch]), (ch, min(widths[ch]),
                                                                      max(widths[ch]))
        assert lo <= fw.servos.min_us[ch] <= fw.servos.max_us[ch] <= hi
