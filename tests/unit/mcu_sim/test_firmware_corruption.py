"""Corrupted frames never actuate: any single damaged byte in an actuating frame is rejected
(counted by the parser, or NACKed), and the outputs stay exactly as they were."""

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.mcu_sim.mcu_host import InProcessHost
from mobigrasp.protocol import (
    FLAG_STOPPED,
    PROTOCOL_VERSION,
    Gripper,
    Hello,
    Nack,
    SetServos,
    SetWheels,
    Stop,
    encode_message,
)

COMMANDS = [
    SetServos(0, (2000, 2400, 700, 800, 2300, 700), 0),
    SetServos(1, (900, 1200, -300, -2500, 2800, -1300), 0),
    Gripper(1000),
    SetWheels(700, -700),
    Stop(),
]

pytestmark = [pytest.mark.both_mcus, pytest.mark.simavr]


@examples(80, derandomize=True)
@given(st.sampled_from(COMMANDS), st.integers(0, 255), st.integers(1, 255), st.integers(0, 200))
def test_one_damaged_byte_never_actuates(cmd, seq, xor, where):
    mcu = Mcu()
    host = InProcessHost(mcu)
    host.send(Hello(PROTOCOL_VERSION, "t", 0), seq=0)
    host.send(SetWheels(0, 0))
    host.run_ms(25)  # first servo period complete
    pulses = mcu.servo_pulses_us()
    wire = bytearray(encode_message(cmd, seq if seq else 1))
    i = where % (len(wire) - 1)  # any byte but the final delimiter
    wire[i] ^= xor
    corrupt_before = mcu.stats()["corrupt_frames"]
    host.send_raw(bytes(wire) + b"\x00")  # a delimiter after, as the next frame would bring
    host.run_ms(45)  # frame on the line, then a full period with whatever was latched
    assert mcu.servo_pulses_us() == pulses
    assert mcu.wheel_duty() == (0, 0)
    assert not host.telemetry()[-1].flags & FLAG_STOPPED
    rejected = mcu.stats()["corrupt_frames"] - corrupt_before
    assert rejected >= 1 or host.messages(Nack)
