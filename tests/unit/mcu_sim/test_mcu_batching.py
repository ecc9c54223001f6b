"""The RX batching of ``Mcu`` (bytes handed to the ISR at the next delimiter) changes nothing the
firmware does: the same inputs give the same output bytes and pulses as one event per byte."""

from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.protocol import (
    PROTOCOL_VERSION,
    Gripper,
    Hello,
    ParamGet,
    SetServos,
    SetWheels,
    Stop,
    encode_message,
)

frames = st.one_of(
    st.builds(lambda q: encode_message(Hello(PROTOCOL_VERSION, "h", 0), q), st.integers(0, 255)),
    st.builds(lambda t, q: encode_message(SetServos(0, (t,) * 6, 100), q), st.integers(500, 2500),
              st.integers(0, 255)),
    st.builds(lambda p, q: encode_message(Gripper(p), q), st.integers(0, 1000),
              st.integers(0, 255)),
    st.builds(lambda v: encode_message(SetWheels(v, -v), 0), st.integers(-1000, 1000)),
    st.builds(lambda q: encode_message(Stop(), q), st.integers(0, 255)),
    st.builds(lambda q: encode_message(ParamGet(1), q), st.integers(0, 255)),
    st.binary(min_size=1, max_size=200),
)
schedule = st.lists(st.tuples(st.integers(0, 40_000), frames), min_size=1, max_size=12)


def run(inputs, batch):
    mcu = Mcu()
    mcu._rx_batch = batch  # 1: a wake-up for every byte, as a per-byte RX interrupt would give
    widths = []
    mcu.subscribe_servo(2, lambda t, w: widths.append((t, w)))
    t = 0
    for gap_us, wire in inputs:
        t += gap_us
        mcu.advance_to(t)
        mcu.uart_rx(wire, t)
        mcu.set_encoder_ticks(t // 100, -(t // 300), t + 20_000)
    mcu.advance_to(t + 200_000)
    out = mcu.uart_tx_take()
    return out, widths, mcu.stats()["rx_ring_overruns"], mcu.firmware.corrupt_frames()


@examples(60)
@given(schedule)
def test_batched_rx_equals_per_byte_rx(inputs):
    assert run(inputs, 127) == run(inputs, 1)
