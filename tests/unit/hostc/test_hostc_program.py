"""The C host as its own program (hostc/main.c, built into the cache) served by the rig's
socket host over a real pty and the shared frame ring, built natively and as the board's
ARMv4T ELF under qemu-arm -cpu ti925t: its HELLO, its DONEs for the same GRANTs,
MCU bytes and camera frames, the bytes it writes to the serial port and its BYE, against the
Python host program served in process with the same task (the idle method: the host program
around a task, without a paper's)."""

from __future__ import annotations

import json
import os
import select
import shutil
import subprocess

import pytest
from rig_fakes import BufferPort, scripted_grants

from mobigrasp import hostc
from mobigrasp.calib import armhost, corpus
from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.handshake import resolved
from mobigrasp.cosim.hosts import SocketHost
from mobigrasp.drivers.lockstep import LockstepClient
from mobigrasp.host.app import HostApp
from mobigrasp.host.app_factory import build_host_app
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.task.machine import TaskOutputs
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.frame import FrameParser
from mobigrasp.services.run_job import host_config, resolve_scenario


class _IdleTask:
    """host/task's shape of hostc/task_idle.c: INIT, no commands, no detectors."""

    def detectors_needed(self):
        return []

    def step(self, now_us, inputs):
        return TaskOutputs(None, None, None, [], "INIT", {}, OpCounts())


def _read_master(fd: int, n: int) -> bytes:
    out = b""
    while len(out) < n:
        ready, _, _ = select.select([fd], [], [], 10.0)
        assert ready, f"the C host wrote {len(out)} of {n} serial bytes"
        out += os.read(fd, n - len(out))
    return out


def _native() -> list[str]:
    return [str(hostc.executable())]


def _armv4t() -> list[str]:
    """The static ARMv4T ELF (make hostc-arm) under an ARMv4T CPU."""
    if not (shutil.which("arm-none-eabi-gcc") and shutil.which("qemu-arm")):
        pytest.skip("arm-none-eabi-gcc and qemu-arm are needed (make arm-tools)")
    return ["qemu-arm", "-cpu", "ti925t", str(armhost.build_elf())]


def _serve_both(host: SocketHost, master: int, app: HostApp, grants) -> int:
    """The same grants (rig_fakes.scripted_grants: grant, its UART bytes) to the C program
    (host) and the Python host program (app), their DONEs and serial bytes compared; the end
    time."""
    port = BufferPort()
    client = LockstepClient(app, port)
    for k, (grant, data) in enumerate(grants):
        os.write(master, data)
        port.rx += data
        want = client.serve(grant)
        client.after_done()
        got = resolved(host.exchange(grant))
        got = ls.decode(ls.encode(got))  # as the rig reads it
        assert got == ls.decode(ls.encode(want)), (k, got, want)
        assert _read_master(master, got.write_bytes) == bytes(port.tx)
        port.tx.clear()
    return grant.until_us


@pytest.mark.parametrize("program", [_native, _armv4t], ids=["native", "armv4t"])
def test_the_c_program_answers_the_rig_as_the_python_host(program):
    master, slave = os.openpty()
    host = SocketHost([*program(), "--port", os.ttyname(slave), "--method", "idle"])
    host.verify_elided = True  # every grant is served and its DONE compared with the predicted
    try:
        app = HostApp(_IdleTask(), {}, lambda app, now, det: det)
        t = _serve_both(host, master, app, scripted_grants())
        bye = host.finish(ls.End(t, "test over"))
        st = app.stats()
        assert bye.stats["control_steps"] == st["control_steps"] > 0
        assert bye.stats["mcu_resets_seen"] == st["mcu_resets_seen"] == 1
        assert bye.stats["state"] == "INIT"
        # the frames crossed the shared ring; the idle method looks for nothing in them
        assert bye.stats["frames_received"] == st["frames_received"] >= 10
        assert bye.stats["frames_idle"] == st["frames_idle"] == st["frames_received"]
        for key in ("arm9_load_max", "arm9_load_mean", "stages",  # the decimals as Python's
                    "mcu", "replans", "path_updates", "close_reason", "circle_error_mm"):
            assert bye.stats[key] == st[key], key
        assert bye.stats["stage_overflow"] == 0
    finally:
        host.close()
        os.close(master)
        os.close(slave)


@pytest.mark.parametrize("args, says", [
    ([], "--port is required"),
    (["--port", "/dev/null", "--method", "003"], "method not in the C host yet"),
    (["--port", "/dev/null", "--poll-ms", "-3"], "--poll-ms"),
    (["--port", "/dev/null", "--config", "/nonexistent.json"], "--config"),
    (["--port", "/nonexistent/tty", "--method", "idle"], "--port"),
    (["--port", "/dev/null", "--bogus", "1"], "unknown option --bogus"),
])
def test_bad_options_exit_2_with_one_line(args, says):
    done = subprocess.run([str(hostc.executable()), *args], capture_output=True, text=True,
                          timeout=30, check=False)
    assert done.returncode == 2
    assert says in done.stderr.splitlines()[0]


def _next_message(fd: int, parser: FrameParser, pending: list) -> m.Message:
    """The next message the host writes to the serial port (waits for bytes, 10 s at most)."""
    while not pending:
        ready, _, _ = select.select([fd], [], [], 10.0)
        assert ready, "the C host wrote nothing for 10 s"
        pending += parser.feed(os.read(fd, 4096))
    return m.decode_frame(pending.pop(0))


def test_free_running_program_opens_the_session_and_keeps_it_alive():
    """Without --lockstep the program runs on the clock (hostc/linux_driver.c): it says HELLO,
    takes the MCU's HELLO_ACK and telemetry, sends heartbeats, logs the trace events, and stops
    with exit 1 and one line when the MCU side closes the port."""
    master, slave = os.openpty()
    tty = os.ttyname(slave)
    proc = subprocess.Popen([str(hostc.executable()), "--port", tty, "--method", "idle"],
                            stderr=subprocess.PIPE, text=True)
    try:
        parser, pending = FrameParser(), []
        hello = _next_message(master, parser, pending)
        assert isinstance(hello, m.Hello) and hello.host_id == "mobigrasp-2440"
        os.write(master, m.encode_message(m.Ack(0), 0) + m.encode_message(
            m.HelloAck(1, "atmega128-fw"), 1) + m.encode_message(m.Telemetry(
                1000, 0, 0, (1500,) * 6, (2500,) * 5, m.FLAG_HANDSHAKE, 0, 0, 0, 0), 2))
        beats = [msg for msg in (_next_message(master, parser, pending) for _ in range(3))]
        assert all(isinstance(msg, m.Heartbeat) for msg in beats), beats
        assert beats[0].time_us < beats[1].time_us < beats[2].time_us
    finally:
        os.close(master)
        _, err = proc.communicate(timeout=30)
        os.close(slave)
    assert proc.returncode == 1
    lines = err.splitlines()  # the trace events, a line a quantum, then the reason it stopped
    assert json.loads(f"[{lines[0]}]")[0]["ev"] == "hello_ack"
    assert lines[-1] == f"mobigrasp-host-c: the MCU side closed the port {tty}; stopping"


@pytest.fixture(scope="module")
def marker_frames(marker_slice) -> list[tuple[int, int, bytes]]:
    """The camera frames of the first 4 s of paper002-marker (conftest.py), in order: the
    board's double cross from the start pose, then nearer."""
    out = []
    for fr in corpus.read_index(marker_slice)["frames"]:
        rgb = corpus.load_frame(marker_slice, fr)
        out.append((rgb.shape[1], rgb.shape[0], rgb.tobytes()))
    assert len(out) >= 8
    return out


@pytest.mark.parametrize("program", [_native, _armv4t], ids=["native", "armv4t"])
def test_the_c_program_runs_002_as_the_python_host(program, marker_frames, tmp_path):
    """Method 002 from paper002-marker's configuration (its camera and parameters) on the
    scenario's recorded frames: the same DONEs (the detectors' modelled ARM9 time included),
    serial bytes and BYE figures as the Python host program."""
    cfg = host_config(resolve_scenario("paper002-marker")[1])
    path = tmp_path / "host.json"
    path.write_text(json.dumps(cfg))
    master, slave = os.openpty()
    host = SocketHost([*program(), "--port", os.ttyname(slave), "--config", str(path)])
    host.verify_elided = True
    try:
        app = build_host_app(cfg)
        t = _serve_both(host, master, app, scripted_grants(
            frame=lambda at: marker_frames[(at // 66_000) % len(marker_frames)]))
        bye = host.finish(ls.End(t, "test over"))
        st = app.stats()
        for key in ("control_steps", "frames_received", "frames_processed", "frames_dropped",
                    "deadline_misses", "state", "arm9_load_max", "arm9_load_mean", "stages",
                    "mcu", "replans", "path_updates", "close_reason", "circle_error_mm"):
            assert bye.stats[key] == st[key], key
        assert st["frames_processed"] > 0 and st["state"] != "INIT"
        # the loads and the means are fractions, the detectors' stages among the stages
        assert 0 < st["arm9_load_mean"] <= st["arm9_load_max"] < 1
        assert len(st["stages"]) > 3 and bye.stats["stage_overflow"] == 0
        assert any(v["mean_us"] != int(v["mean_us"]) for v in st["stages"].values())
    finally:
        host.close()
        os.close(master)
        os.close(slave)
