"""Joint limits are never exceeded, whatever the host sends: property tests over command sequences
that mix valid commands, out-of-range raw payloads, garbage and bit-flipped frames."""

import struct

import pytest
from hypothesis import HealthCheck, given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.mcu_sim.firmware.servo_table import default_limits_us
from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.mcu_sim.mcu_host import InProcessHost
from mobigrasp.protocol import (
    PROTOCOL_VERSION,
    Frame,
    Gripper,
    Hello,
    ParamSet,
    SetServos,
    SetWheels,
    encode_frame,
    encode_message,
)

LIMITS = [default_limits_us(ch) for ch in range(6)]

pytestmark = [pytest.mark.both_mcus, pytest.mark.simavr]


def raw_servos(mode, targets, slew, seq):
    payload = struct.pack("<B6hH", mode, *targets, slew)
    return encode_frame(Frame(PROTOCOL_VERSION, seq, SetServos.MSG_TYPE, payload))


def raw_wheels(left, right, seq):
    payload = struct.pack("<hh", left, right)
    return encode_frame(Frame(PROTOCOL_VERSION, seq, SetWheels.MSG_TYPE, payload))


seqs = st.integers(0, 255)
actions = st.one_of(
    st.builds(lambda t, s, q: encode_message(SetServos(0, tuple(t), s), q),
              st.lists(st.integers(500, 2500), min_size=6, max_size=6), st.integers(0, 4000), seqs),
    st.builds(lambda t, s, q: encode_message(SetServos(1, tuple(t), s), q),
              st.lists(st.integers(-3142, 3142), min_size=6, max_size=6), st.integers(0, 4000),
              seqs),
    st.builds(raw_servos, st.integers(0, 3), st.lists(st.integers(-32768, 32767), min_size=6,
                                                      max_size=6), st.integers(0, 65535), seqs),
    st.builds(lambda p, q: encode_message(Gripper(p), q), st.integers(0, 1000), seqs),
    st.builds(raw_wheels, st.integers(-32768, 32767), st.integers(-32768, 32767), seqs),
    st.binary(min_size=1, max_size=80),
    st.builds(lambda w, i: w[:i] + bytes([w[i] ^ 0x10]) + w[i + 1:],
              st.builds(lambda q: encode_message(SetServos(0, (2500,) * 6, 0), q), seqs),
              st.integers(0, 10)),
)


def run_sequence(cmds, extra_param=None, sampled=False):
    """Widths in ns of every pulse per channel (``sampled``: the last complete pulse read each
    millisecond, for a backend that does not report each period; a 20 ms period is sampled
    about 20 times), and the wheel duties each millisecond."""
    mcu = Mcu()
    widths = {ch: [] for ch in range(6)}
    if not sampled:
        for ch in range(6):
            mcu.subscribe_servo(ch, lambda t, w, ch=ch: widths[ch].append(w))
    host = InProcessHost(mcu)

    def run_ms(ms):
        for _ in range(ms):
            host.run_ms(1)
            duties.append(mcu.wheel_duty())
            if sampled:
                for ch, us in enumerate(mcu.servo_pulses_us()):
                    if us or widths[ch]:  # 0 until the first period after start-up ends
                        widths[ch].append(us * 1000)

    duties = []
    host.send(Hello(PROTOCOL_VERSION, "prop", 0))
    run_ms(5)
    if extra_param is not None:
        host.send(extra_param)
        run_ms(5)
    for wire, wait_ms in cmds:
        host.send_raw(wire)
        run_ms(wait_ms)
    run_ms(45)
    return mcu, widths, duties


# mcu_backend is only the backend's name, the same for every example
@examples(60,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.tuples(actions, st.integers(1, 30)), min_size=1, max_size=8))
def test_pulses_stay_within_joint_limits(mcu_backend, cmds):
    mcu, widths, duties = run_sequence(cmds, sampled=mcu_backend == "simavr")
    for ch in range(6):
        lo, hi = LIMITS[ch]
        assert widths[ch], "every channel keeps pulsing"
        assert all(lo * 1000 <= w <= hi * 1000 for w in widths[ch]), (ch, min(widths[ch]),
                                                                      max(widths[ch]))
    assert all(-255 <= d <= 255 for pair in duties for d in pair)
    if mcu_backend != "simavr":  # the ELF's wheel targets are not read off the core
        assert all(abs(w.target_mmps) <= 800 for w in mcu.firmware.wheels)


@pytest.mark.not_on("simavr", "reads the Python firmware's servo limit table")
@examples(30)
@given(st.integers(0, 5), st.integers(500, 2500), st.integers(0, 5), st.integers(500, 2500),
       st.lists(st.tuples(actions, st.integers(1, 20)), min_size=1, max_size=5))
def test_limit_params_bound_pulses_once_in_force(ch_min, vmin, ch_max, vmax, cmds):
    mcu, widths, _ = run_sequence(cmds, ParamSet(16 + ch_min, vmin))
    host = InProcessHost(mcu)
    host.send(ParamSet(24 + ch_max, vmax), seq=200)
    host.run_ms(45)  # one period to latch the clamped value
    servos = mcu.firmware.servos
    for ch in range(6):
        assert servos.min_us[ch] <= servos.max_us[ch]
        assert 500 <= servos.min_us[ch] and servos.max_us[ch] <= 2500
        assert all(500_000 <= w <= 2_500_000 for w in widths[ch])
        w = mcu.servo_pulse_ns(ch)
        assert servos.min_us[ch] * 1000 <= w <= servos.max_us[ch] * 1000, ch
