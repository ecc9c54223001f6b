"""``mobigrasp mcu`` as a separate process on a real pty, driven by ``mobigrasp console``."""

import io
import subprocess
import sys
from pathlib import Path

import pytest

from mobigrasp.link.messages import Link
from mobigrasp.link.registry import open_transport
from mobigrasp.tools.cli import main
from mobigrasp.tools.commands.console import ConsoleShell

ROOT = Path(__file__).resolve().parents[3]
SAFETY_S = 60  # generous limits only; nothing asserts on speed


@pytest.fixture
def mcu_process():
    proc = subprocess.Popen(
        [sys.executable, "-m", "mobigrasp.tools.cli", "mcu", "--speed", "1"],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        port = proc.stdout.readline().strip()
        assert port.startswith("/dev/"), port
        yield proc, port
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait(SAFETY_S)


def test_console_session_against_the_standalone_mcu(mcu_process):
    proc, port = mcu_process
    script = "\n".join([
        "hello",
        "servos 1500 1600 1700 1500 1500 1500",
        "servos-mrad 0 0 -1571 -1571 1571 0 200",
        "servos 100 1500 1500 1500 1500 1500",
        "gripper 1000",
        "wheels 200 200",
        "param get watchdog_ms",
        "param set telemetry_hz 20",
        "param set watchdog_ms 99999",
        "param get no_such_param",
        "frobnicate",
        "telemetry",
        "stop",
        "quit",
    ]) + "\n"
    out = io.StringIO()
    with Link(open_transport(port)) as link:
        shell = ConsoleShell(link, reply_timeout_s=SAFETY_S, stdin=io.StringIO(script), stdout=out)
        shell.prompt = ""
        shell.cmdloop()
    text = out.getvalue()
    assert "HELLO_ACK firmware=mobigrasp-avr protocol=1" in text
    assert text.count("ACK seq=") >= 6
    assert "watchdog_ms = 250" in text
    assert "telemetry_hz = 20" in text
    assert "reason=BAD_PARAM" in text  # watchdog_ms 99999: a safety PARAM out of its range
    assert "refused:" in text  # 100 µs rejected before sending; unknown parameter name
    assert "unknown command 'frobnicate'" in text
    assert "servo_us=[" in text and "flags=0x" in text
    # Closing the host side ends the MCU process with a message.
    _, err = proc.communicate(timeout=SAFETY_S)
    assert proc.returncode == 1  # the host going away is reported as a failure
    assert "the host closed the port" in err
    assert "+2.12 %" in err  # baud error reported at start-up


def test_bad_arguments_are_reported(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["mcu", "--speed", "fast"])
    assert exc.value.code == 2 and "--speed" in capsys.readouterr().err
    assert main(["mcu", "--param", "nope=1", "--duration", "0.1"]) == 2
    assert "unknown parameter 'nope'" in capsys.readouterr().err
    assert main(["console", "--port", "/dev/nonexistent-mobigrasp-port"]) == 2
    assert "cannot open" in capsys.readouterr().err


def test_console_ends_cleanly_when_the_mcu_goes_away():
    from mobigrasp.mcu_sim.mcu_pty import PtyMcu

    pty = PtyMcu()
    out = io.StringIO()
    with Link(open_transport(pty.port)) as link:
        pty.close()  # the MCU vanishes before the user types anything
        shell = ConsoleShell(link, reply_timeout_s=2.0, stdin=io.StringIO("telemetry\nhello\n"),
                             stdout=out)
        shell.prompt = ""
        shell.cmdloop()
    assert "port closed" in out.getvalue() or "send failed" in out.getvalue()
    assert shell.port_closed


def test_mcu_bench_figures_have_units_and_plausible_counts():
    import argparse

    from mobigrasp.tools.benches import mcu as bench

    res = bench.run(argparse.Namespace(seconds=2, telemetry_hz=50, command_hz=50))
    assert res["sim_s"] == 2 and res["sim_s_per_wall_s"] > 0
    assert res["realtime_factor"] == res["sim_s_per_wall_s"]
    assert 100 <= res["frames_from_mcu"] <= 110  # 2 s x 50 Hz telemetry + ACKs
    assert res["corrupt_frames"] == 0
    assert res["wheel_speed_left_mmps"] == pytest.approx(300, abs=10)  # second 1..2: 300 mm/s
