"""RX ring buffer: batched puts equal byte-by-byte ISR puts; overruns counted; the SET_WHEELS fast
path of the firmware agrees with the protocol decoder."""

import struct

import pytest
from hypothesis import HealthCheck, given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.mcu_sim.firmware.ring import ByteRing
from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.mcu_sim.mcu_host import InProcessHost
from mobigrasp.protocol import (
    NACK_BAD_LENGTH,
    NACK_OUT_OF_RANGE,
    PROTOCOL_VERSION,
    Frame,
    Hello,
    Nack,
    encode_frame,
)

pytestmark = [pytest.mark.both_mcus, pytest.mark.simavr]


@pytest.mark.not_on("simavr", "the Python ByteRing alone: no MCU in it")
@examples(150)
@given(st.integers(2, 64), st.lists(st.tuples(st.binary(max_size=80), st.booleans()), max_size=12))
def test_put_bytes_equals_repeated_put(size, ops):
    a, b = ByteRing(size), ByteRing(size)
    for data, drain in ops:
        for byte in data:
            a.put(byte)
        b.put_bytes(data)
        assert len(a) == len(b) <= size - 1
        assert a.overruns == b.overruns
        if drain:
            assert a.take_all() == b.take_all()
    assert a.take_all() == b.take_all()


# mcu_backend is only the backend's name, the same for every example
@examples(80,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.integers(-32768, 32767), st.integers(-32768, 32767), st.sampled_from([3, 4, 5]))
def test_set_wheels_fast_path_matches_the_protocol(mcu_backend, left, right, length):
    mcu = Mcu()
    host = InProcessHost(mcu)
    host.send(Hello(PROTOCOL_VERSION, "t", 0), seq=0)
    payload = struct.pack("<hh", left, right)[:length] + b"\x00" * max(0, length - 4)
    host.send_raw(encode_frame(Frame(PROTOCOL_VERSION, 77, 0x12, payload)))
    host.run_ms(15)
    nacks = host.messages(Nack)
    if length != 4:
        assert nacks == [Nack(77, NACK_BAD_LENGTH)]
    elif abs(left) > 1000 or abs(right) > 1000:
        assert nacks == [Nack(77, NACK_OUT_OF_RANGE)]
        assert mcu.wheel_duty() == (0, 0)
        if mcu_backend != "simavr":  # the ELF's wheel targets are not read off the core
            assert mcu.firmware.wheels[0].target_mmps == 0
    else:
        assert nacks == []
        want = max(-800, min(800, left))
        if mcu_backend != "simavr":
            assert mcu.firmware.wheels[0].target_mmps == want
