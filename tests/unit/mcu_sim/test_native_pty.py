"""The native backend behind a real pty: the pytest plugin's fixture with mcu="native" serves a
host like the Python model does, and the CLI names an unknown backend."""

import subprocess
import sys

from mobigrasp.protocol import PROTOCOL_VERSION, Ack, Hello, SetServos


def _session(emu):
    seq = emu.send(Hello(PROTOCOL_VERSION, "pty", 0))
    emu.advance_ms(12)
    got = emu.receive(2)
    emu.send(SetServos(0, (1500, 1700, 1500, 1500, 1500, 1500), 0))
    emu.advance_ms(45)
    # the firmware's counters; the ``avr_*`` figures are the Python model's report of the
    # AVR's cycles (mcu_sim/firmware/cycles.py), which the C run on the host has not
    counters = {k: v for k, v in emu.stats.items() if not k.startswith("avr_")}
    return seq, got, emu.servo_pulses_us(), emu.telemetry()[-1], counters


def test_native_fixture_over_the_pty_matches_the_python_model(emulated_mcu_factory):
    native = _session(emulated_mcu_factory(mcu="native"))
    python = _session(emulated_mcu_factory(mcu="python"))
    seq, got, pulses, tel, stats = native
    assert Ack(seq) in got and pulses[1] == 1700.0 and tel.flags & 4
    assert native == python


def test_mcu_command_rejects_an_unknown_backend():
    res = subprocess.run([sys.executable, "-m", "mobigrasp", "mcu", "--mcu", "verilog",
                          "--duration", "0.1"], capture_output=True, text=True, timeout=60)
    assert res.returncode == 2
    assert "verilog" in res.stderr and "native" in res.stderr and "Traceback" not in res.stderr
