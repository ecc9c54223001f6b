"""The C host as a free-running Linux program (hostc/linux_driver.c) against ``mobigrasp sim`` in
wall time, two processes: the serial pty and the raw-frame endpoint (``sim --raw-frames``,
``--camera unix:PATH``), as on the board with /dev/ttySAC1 and the camera."""

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from mobigrasp import hostc


def _native() -> list[str]:
    return [str(hostc.executable())]


def _armv4t() -> list[str]:
    """The board's ELF under an ARMv4T CPU (the tools are installed here: make arm-tools)."""
    from mobigrasp.calib.armhost import build_elf

    return ["qemu-arm", "-cpu", "ti925t", str(build_elf())]


def _host(robot, raw: Path, method: str, program=_native) -> subprocess.CompletedProcess:
    """The C program on the robot's port and frames until the session ends (it closes the
    port); its exit code and stderr (the trace events, then its figures)."""
    return subprocess.run([*program(), "--port", robot.port, "--method", method,
                           "--camera", f"unix:{raw}"], capture_output=True, text=True,
                          timeout=600, check=False)


def _stats(stderr: str) -> dict:
    line = next(x for x in stderr.splitlines() if x.startswith("mobigrasp-host-c: stats "))
    return json.loads(line[len("mobigrasp-host-c: stats "):])


@pytest.mark.parametrize("program", [_native, _armv4t], ids=["native", "armv4t"])
def test_c_host_reads_the_simulations_raw_frames(emulated_robot, program):
    with tempfile.TemporaryDirectory(prefix="mg-rf-") as tmp:  # a short AF_UNIX path
        raw = Path(tmp) / "frames.sock"
        robot = emulated_robot("paper000-exp1", speed=2.0, plots=False, time_limit_s=3.0,
                               raw_frames=raw)
        done = _host(robot, raw, "idle", program)
        summary = robot.summary
        assert not raw.exists()  # the session removed its socket
    assert done.returncode == 1, done.stderr  # the session ended and closed the port
    stats = _stats(done.stderr)
    # every frame sent to it read whole (but the one the session's end may cut), at whatever
    # speed: a client that lags gets the newest frames, never a torn one
    sent = summary["camera_frames"]["raw_sent"]
    assert sent - 1 <= stats["frames_received"] <= sent and stats["frames_received"] >= 10
    assert stats["frames_idle"] == stats["frames_received"]  # the idle method looks at none
    assert stats["protocol"]["crc_errors"] == 0 and stats["protocol"]["rx_frames"] > 100
    assert summary["raw_frames"] == f"unix:{raw}"
    assert summary["end_reason"] == "time_limit"


def test_raw_frames_path_taken_is_refused_and_kept(tmp_path):
    taken = tmp_path / "taken.sock"
    taken.write_text("not ours")
    done = subprocess.run([sys.executable, "-m", "mobigrasp", "sim", "paper000-exp1",
                           "--raw-frames", str(taken),
                           "--out", str(tmp_path / "sim"), "--no-plots"],
                          capture_output=True, text=True, timeout=120, check=False,
                          stdin=subprocess.DEVNULL)
    assert done.returncode == 2
    assert "--raw-frames" in done.stderr.strip().splitlines()[-1]
    assert taken.read_text() == "not ours"


def test_bad_camera_source_is_one_line(tmp_path):
    for source, says in (("rtsp://x", "--camera must be unix:PATH"),
                         (f"unix:{tmp_path}/none.sock", "cannot connect")):
        done = subprocess.run([str(hostc.executable()), "--port", "/dev/null", "--method",
                               "idle", "--camera", source], capture_output=True, text=True,
                              timeout=30, check=False)
        assert done.returncode == 2 and says in done.stderr.splitlines()[0], done.stderr


@pytest.mark.slow
def test_c_host_grasps_paper000_exp1_against_the_simulation(emulated_robot):
    """In real time, two processes: the C host with 000 grasps."""
    with tempfile.TemporaryDirectory(prefix="mg-rf-") as tmp:
        raw = Path(tmp) / "frames.sock"
        robot = emulated_robot("paper000-exp1", plots=False, raw_frames=raw)
        done = _host(robot, raw, "000")
        robot.stop()
        summary = robot.summary
    assert done.returncode == 0, done.stderr[-2000:]
    assert summary["grasped"] and summary["contacts"] == 0
