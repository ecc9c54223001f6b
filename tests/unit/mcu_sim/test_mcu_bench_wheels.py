"""The standalone MCU as people use it: bench wheels, NACK reasons by name, integer pulse widths,
wait_from_host without byte counting."""

import os
import subprocess
import sys

import pytest

from mobigrasp.link.messages import Link
from mobigrasp.link.registry import open_transport
from mobigrasp.mcu_sim.backend import MCU_BACKENDS
from mobigrasp.mcu_sim.mcu_pty import WHEELS
from mobigrasp.mcu_sim.wire_names import describe, flag_names, nack_reason_name
from mobigrasp.protocol import (
    FLAG_GRIPPER_CLOSED,
    FLAG_HANDSHAKE,
    PROTOCOL_VERSION,
    Hello,
    Nack,
    SetServos,
    SetWheels,
    Telemetry,
    encode_message,
)
from mobigrasp.tools.commands import mcu as mcu_command


def handshake(emu):
    emu.advance_ms(20)  # the ELF under simavr needs 2.2 ms of start-up (docs/firmware.md)
    emu.send(Hello(PROTOCOL_VERSION, "pytest", 0))
    emu.advance_ms(12)
    emu.receive(3)


@pytest.mark.parametrize("backend", sorted(MCU_BACKENDS))
def test_bench_wheels_turn_the_encoders_with_lag(emulated_mcu_factory, backend):
    emu = emulated_mcu_factory(mcu=backend)
    handshake(emu)
    emu.send(SetWheels(200, 200))
    emu.advance_ms(40)
    early = emu.telemetry()[-1]
    emu.advance_ms(200)  # under the 250 ms watchdog
    late = emu.telemetry()[-1]
    assert 0 < early.enc_left < late.enc_left
    assert 0 < early.enc_right < late.enc_right
    # the counts grow faster later: the motor lags behind the duty at first
    rate_early = early.enc_left / (early.time_us / 1e6)
    rate_late = (late.enc_left - early.enc_left) / ((late.time_us - early.time_us) / 1e6)
    assert rate_late > rate_early


def test_still_wheels_keep_the_counts_at_zero(emulated_mcu_factory):
    emu = emulated_mcu_factory(wheels="still")
    handshake(emu)
    emu.send(SetWheels(200, 200))
    emu.advance_ms(200)
    tel = emu.telemetry()[-1]
    assert (tel.enc_left, tel.enc_right) == (0, 0)


def test_unknown_wheel_plant_or_backend_is_refused_by_name(emulated_mcu_factory):
    with pytest.raises(ValueError, match="wheels must be one of bench, still"):
        emulated_mcu_factory(wheels="air")
    with pytest.raises(ValueError, match="unknown MCU backend 'avr'"):
        emulated_mcu_factory(mcu="avr")


def test_the_command_offers_the_plants_of_the_pty_mcu():
    assert mcu_command.WHEELS == WHEELS


def test_pulse_widths_are_whole_microseconds(emulated_mcu):
    emu = emulated_mcu
    handshake(emu)
    emu.send(SetServos(0, (1200, 1001, 1800, 2000, 1000, 2100), 0))
    emu.advance_ms(100)
    pulses = emu.servo_pulses_us()
    assert all(type(p) is int for p in pulses)
    assert pulses[1] == 1001 and pulses[5] == 2100


def test_nacks_are_listed_by_reason_name(emulated_mcu):
    emu = emulated_mcu
    seq = emu.send(SetServos(0, (1500,) * 6, 0))  # before HELLO
    emu.advance_ms(10)
    assert (seq, "NOT_READY") in emu.nacks()
    assert emu.describe(Nack(seq, 6)) == f"NACK seq={seq} reason=BAD_VERSION"


def test_wait_from_host_needs_no_byte_count(emulated_mcu):
    """Bytes written straight to the port by someone else (not the fixture's host end) are on the
    RX line after one wait_from_host(), before any simulated time passes."""
    emu = emulated_mcu
    fd = os.open(emu.port, os.O_RDWR | os.O_NOCTTY)
    try:
        wire = encode_message(Hello(PROTOCOL_VERSION, "raw", 0), 1)
        for _ in range(20):
            os.write(fd, wire)
        before = emu.stats["rx_bytes"]
        assert emu.wait_from_host()
        assert emu.bytes_from_host == 20 * len(wire)
        emu.advance_ms(60)
        assert emu.stats["rx_bytes"] - before == 20 * len(wire)
    finally:
        os.close(fd)


def test_flag_and_reason_names():
    assert flag_names(FLAG_HANDSHAKE | FLAG_GRIPPER_CLOSED) == ["HANDSHAKE", "GRIPPER_CLOSED"]
    assert flag_names(1 << 7) == ["bit_7"]
    assert nack_reason_name(4) == "NOT_READY" and nack_reason_name(99) == "reason_99"
    tel = Telemetry(5, 1, 2, (1500,) * 6, (0xFFFF,) * 5, FLAG_HANDSHAKE, 0, 0, 0, 0)
    assert "flags=HANDSHAKE " in describe(tel)


def test_mcu_command_logs_nacks_by_name():
    """`mobigrasp mcu --log replies`: a command before HELLO is NACKed, printed by name, and
    counted by reason on the last line."""
    proc = subprocess.Popen([sys.executable, "-m", "mobigrasp", "mcu", "--speed", "max",
                             "--log", "replies"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        port = proc.stdout.readline().strip()
        link = Link(open_transport(port))
        link.send_with_seq(SetServos(0, (1500,) * 6, 0), 7)
        got = []
        while not any(isinstance(m, Nack) for m in got) and link.wait(30.0):
            got += [r.msg for r in link.poll()]
        link.close()  # the host closes the port: the MCU ends
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert Nack(7, 4) in got
    assert proc.returncode == 1  # the host went away
    assert "NACK seq=7 reason=NOT_READY" in err
    assert "NACKs sent: NOT_READY 1" in err
