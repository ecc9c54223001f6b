"""The firmware's duplicate filter (docs/protocol.md §5.2): a copy is the same seq AND the same
content; the window is counted in the sender's sequence numbers, not in time or in commands; a
reused seq with other content is NACKed, never ACKed and dropped."""

import pytest

from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.mcu_sim.mcu_host import InProcessHost
from mobigrasp.protocol import (
    NACK_SEQ_REUSED,
    PROTOCOL_VERSION,
    Ack,
    Hello,
    Nack,
    SetServos,
    SetWheels,
    encode_message,
)

pytestmark = [pytest.mark.both_mcus, pytest.mark.simavr]


def ready():
    mcu = Mcu()
    host = InProcessHost(mcu)
    host.send(Hello(PROTOCOL_VERSION, "t", 0), seq=0)
    host.run_ms(12)
    host.clear()
    return mcu, host


def servos(ch1_us):
    return SetServos(0, (1500, ch1_us, 1500, 1500, 1500, 1500), 0)


def ch1(mcu):
    return mcu.servo_pulse_us(1)


def answers(host, seq):
    return [m for m in host.messages() if isinstance(m, Ack | Nack) and m.acked_seq == seq]


def test_a_copy_arriving_more_than_250_ms_later_is_not_executed_again():
    mcu, host = ready()
    wire = encode_message(servos(1600), 1)
    host.send_raw(wire)
    host.run_ms(45)
    host.send(servos(1500), seq=2)
    host.run_ms(400)  # longer than the old 250 ms expiry
    host.send_raw(wire)
    host.run_ms(45)
    assert ch1(mcu) == 1500
    assert answers(host, 1) == [Ack(1), Ack(1)]
    assert mcu.stats()["duplicates"] == 1


def test_a_copy_after_16_other_reliable_commands_is_not_executed_again():
    mcu, host = ready()
    wire = encode_message(servos(1600), 1)
    host.send_raw(wire)
    host.run_ms(30)
    for k in range(17):  # 17 other reliable commands, the last one leaves ch1 at 1500
        host.send(servos(1700 + 10 * k if k < 16 else 1500), seq=2 + k)
        host.run_ms(25)
    host.send_raw(wire)
    host.run_ms(45)
    assert ch1(mcu) == 1500
    assert answers(host, 1) == [Ack(1), Ack(1)]


def test_a_reused_seq_with_other_content_within_250_ms_is_nacked_not_dropped():
    mcu, host = ready()
    host.send(servos(1600), seq=1)
    host.run_ms(30)
    host.send(servos(1900), seq=1)
    host.run_ms(30)
    assert answers(host, 1) == [Ack(1), Nack(1, NACK_SEQ_REUSED)]
    assert ch1(mcu) == 1600  # refused and said so: the sender knows it did not run


def test_a_true_retransmission_is_still_deduplicated():
    mcu, host = ready()
    wire = encode_message(servos(1600), 1)
    host.send_raw(wire)
    host.run_ms(20)  # the ACK was lost: the sender resends the same bytes after 20 ms
    host.send(servos(1500), seq=2)  # meanwhile a newer command ran (it may have been cancelled
    host.run_ms(5)  # at the sender, but its copy was already on the wire)
    host.send_raw(wire)
    host.run_ms(45)
    assert answers(host, 1) == [Ack(1), Ack(1)]
    assert ch1(mcu) == 1500


def test_a_retransmission_whose_original_was_lost_runs_after_newer_unreliable_frames():
    mcu, host = ready()
    wire = encode_message(servos(1600), 3)  # the first copy never arrived
    host.send(SetWheels(0, 0), seq=4)
    host.send(SetWheels(0, 0), seq=5)
    host.run_ms(20)
    host.send_raw(wire)
    host.run_ms(45)
    assert answers(host, 3) == [Ack(3)]
    assert ch1(mcu) == 1600
