"""The C firmware (native backend) and the Python model are one behaviour: the same random byte
streams, encoder motion, sonar ranges, resets and clock advances give identical servo pulses,
wheel duties, bytes on the TX line and counters."""

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.mcu_sim.firmware.params import PARAM_TABLE
from mobigrasp.mcu_sim.mcu import Mcu, McuConfig
from mobigrasp.mcu_sim.native.firmware import c_param_table
from mobigrasp.mcu_sim.native.mcu import NativeMcu
from mobigrasp.protocol import (
    PROTOCOL_VERSION,
    Frame,
    Gripper,
    Heartbeat,
    Hello,
    ParamGet,
    ParamSet,
    SetServos,
    SetWheels,
    Stop,
    encode_frame,
    encode_message,
)

PARAM_IDS = [row[0] for row in PARAM_TABLE] + [0, 8, 99, 101, 65535]

u8 = st.integers(0, 255)
messages = st.one_of(
    st.builds(Hello, st.sampled_from([PROTOCOL_VERSION, PROTOCOL_VERSION + 1]),
              st.text("abcxyz", max_size=16), st.integers(0, 0xFFFF)),
    st.builds(SetServos, st.just(0), st.tuples(*[st.integers(500, 2500)] * 6),
              st.integers(0, 0xFFFF)),
    st.builds(SetServos, st.just(1), st.tuples(*[st.integers(-3142, 3142)] * 6),
              st.integers(0, 0xFFFF)),
    st.builds(Gripper, st.integers(0, 1000)),
    st.builds(SetWheels, st.integers(-1000, 1000), st.integers(-1000, 1000)),
    st.builds(Stop),
    st.builds(Heartbeat, st.integers(0, 0xFFFF_FFFF)),
    st.builds(ParamGet, st.sampled_from(PARAM_IDS)),
    st.builds(ParamSet, st.sampled_from(PARAM_IDS),
              st.one_of(st.integers(-5, 3000), st.integers(-2**31, 2**31 - 1))),
)
wire_chunks = st.one_of(
    st.tuples(messages, u8).map(lambda ms: encode_message(ms[0], ms[1])),
    # any type, any payload: NACKs of every reason, unknown types, replies the MCU ignores
    st.builds(lambda v, s, t, p: encode_frame(Frame(v, s, t, p)),
              st.sampled_from([PROTOCOL_VERSION, PROTOCOL_VERSION, 0, 2]), u8,
              st.sampled_from([0x01, 0x02, 0x03, 0x10, 0x11, 0x12, 0x13, 0x20, 0x30, 0x31,
                               0x32, 0x40, 0x41, 0x50, 0x77]), st.binary(max_size=64)),
    st.binary(max_size=90),  # garbage, runts, oversize runs
    # a frame whose delimiter was lost, merged with the next (recovered), or cut short
    st.tuples(messages, u8, messages, u8, st.integers(0, 60)).map(
        lambda m: encode_message(m[0], m[1])[:-1][m[4]:] + encode_message(m[2], m[3])),
    st.tuples(messages, u8, st.integers(0, 10_000)).map(
        lambda m: _flip(encode_message(m[0], m[1]), m[2])),
)


def _flip(wire: bytes, bit: int) -> bytes:
    b = bytearray(wire)
    i = bit // 8 % len(b)
    b[i] ^= 1 << (bit % 8)
    return bytes(b)


ops = st.lists(st.one_of(
    st.tuples(st.just("rx"), wire_chunks),
    st.tuples(st.just("advance"), st.integers(0, 60_000)),
    st.tuples(st.just("enc"), st.integers(-400, 400), st.integers(-400, 400),
              st.integers(0, 30_000)),
    st.tuples(st.just("sonar"), st.lists(st.one_of(st.none(), st.floats(0.0, 3.0)),
                                         min_size=5, max_size=5)),
    st.tuples(st.just("reset")),
    st.tuples(st.just("again")),  # the last chunk once more: a retransmitted copy
), max_size=40)


def _counters(mcu):
    # the firmware's counters; the ``avr_*`` timing figures are the Python model's report of
    # the AVR's cycles (mcu_sim/firmware/cycles.py), which the C run on the host has not
    return {k: v for k, v in mcu.stats().items() if not k.startswith("avr_")}


def _observe(mcu):
    return (mcu.now_us, mcu.servo_pulses_us(), mcu.wheel_duty(), mcu.uart_tx_take(),
            _counters(mcu), mcu.tx_idle_through_us())


def _drive(mcu, program, params):
    log = []
    enc = [0, 0]
    last = b""
    for op in program:
        kind = op[0]
        if kind == "rx":
            mcu.uart_rx(op[1])
            last = op[1]
        elif kind == "again":
            mcu.uart_rx(last)
        elif kind == "advance":
            mcu.advance_to(mcu.now_us + op[1])
        elif kind == "enc":
            enc[0] += op[1]
            enc[1] += op[2]
            mcu.set_encoder_ticks(enc[0], enc[1], mcu.now_us + op[3])
        elif kind == "sonar":
            ranges = op[1]
            mcu.set_sonar_provider(lambda i, r=ranges: r[i])
        else:
            mcu.reset()
        log.append(_observe(mcu))
    mcu.advance_to(mcu.now_us + 300_000)  # watchdog, telemetry and slews run out
    log.append(_observe(mcu))
    return log


@examples(200)
@given(program=ops, hz=st.sampled_from([0, 50, 100]), wd=st.sampled_from([50, 60, 250]))
def test_same_inputs_same_outputs(program, hz, wd):
    params = {"telemetry_hz": hz, "watchdog_ms": wd}
    start = [encode_message(Hello(PROTOCOL_VERSION, "t", 0), 0)]
    program = [("rx", w) for w in start] + list(program)
    python = _drive(Mcu(McuConfig(params=params)), program, params)
    native = _drive(NativeMcu(McuConfig(params=params)), program, params)
    assert native == python


def test_two_native_mcus_keep_their_own_state():
    a, b = NativeMcu(), NativeMcu()
    ref = Mcu()
    a.uart_rx(encode_message(Hello(PROTOCOL_VERSION, "a", 0), 0))
    ref.uart_rx(encode_message(Hello(PROTOCOL_VERSION, "a", 0), 0))
    for mcu in (a, b, ref):
        mcu.advance_to(50_000)
    for mcu in (a, ref):
        mcu.uart_rx(encode_message(SetServos(0, (1500, 2000, 1500, 1500, 1500, 1500), 0), 1))
    for mcu in (a, b, ref):
        mcu.advance_to(100_000)
    assert a.servo_pulses_us() == ref.servo_pulses_us() != b.servo_pulses_us()
    assert a.firmware.handshake and not b.firmware.handshake
    assert a.uart_tx_take() == ref.uart_tx_take()


def test_c_param_table_is_the_python_one():
    assert c_param_table() == tuple((r[0], r[2], r[3], r[4], r[5], r[6]) for r in PARAM_TABLE)


@pytest.mark.parametrize("jump", [100_000, -100_000, 2**31 - 1])
def test_encoder_jump_beyond_int32_products(jump):
    # A count that moves by more than 8191 ticks in one 10 ms period (a broken encoder or an
    # injected fault): kp x error would leave an int32 in C; both clamp the delta first
    # (wheel_pi WHEEL_DELTA_MAX_TICKS) and drive the wheel at full duty against it.
    outs = []
    for cls in (Mcu, NativeMcu):
        mcu = cls(McuConfig(params={"wheel_kp": 1000}))
        mcu.uart_rx(encode_message(Hello(PROTOCOL_VERSION, "t", 0), 0))
        mcu.advance_to(20_000)
        mcu.uart_rx(encode_message(SetWheels(100, 100), 1))
        mcu.advance_to(35_000)
        mcu.set_encoder_ticks(jump, jump)
        mcu.advance_to(45_000)  # the 40 ms control period saw the jump
        outs.append((mcu.wheel_duty(), mcu.uart_tx_take()))
    assert outs[0] == outs[1]
    assert outs[0][0] == ((-255, -255) if jump > 0 else (255, 255))


def test_c_joint_table_is_protocol_joints():
    from mobigrasp.mcu_sim.firmware.servo_table import mrad_slew_to_us
    from mobigrasp.mcu_sim.native.firmware import ffi, lib
    from mobigrasp.protocol import joints

    lo, hi = ffi.new("int16_t *"), ffi.new("int16_t *")
    for ch in range(joints.N_CHANNELS):
        lib.joint_mech_limits_us(ch, lo, hi)
        assert (lo[0], hi[0]) == joints.MECH_LIMITS_US[ch]
        # every int16 angle: the products stay inside an int32 in C
        assert [lib.joint_pulse_us(ch, v) for v in range(-32768, 32768, 7)] == \
            [joints.pulse_us(ch, v) for v in range(-32768, 32768, 7)]
    # every u16 slew: 65535 x 33215 needs the C's unsigned arithmetic
    assert [lib.mrad_slew_to_us(s) for s in range(0, 65536)] == \
        [mrad_slew_to_us(s) for s in range(0, 65536)]


@pytest.mark.parametrize("front", [
    encode_message(SetServos(0, (1500,) * 6, 0), 9)[:-1],  # the delimiter of a frame lost
    bytes(range(1, 101)),  # an oversize run of garbage glued to the frame
    encode_message(Gripper(500), 3)[:5],  # a frame cut short by a sender reset
])
def test_frame_after_a_lost_delimiter_is_recovered_by_both(front):
    wire = front + encode_message(SetServos(0, (1500, 1800, 1500, 1500, 1500, 1500), 0), 1)
    outs = []
    for cls in (Mcu, NativeMcu):
        mcu = cls()
        mcu.uart_rx(encode_message(Hello(PROTOCOL_VERSION, "t", 0), 0))
        mcu.advance_to(20_000)
        mcu.uart_rx(wire)
        mcu.advance_to(80_000)
        outs.append((mcu.servo_pulses_us(), _counters(mcu), mcu.uart_tx_take()))
    assert outs[0] == outs[1]
    pulses, stats, _ = outs[0]
    assert pulses[1] == 1800.0 and stats["parser_recovered"] == 1
    assert stats["parser_garbage_bytes"] == len(front)
