"""``mobigrasp console`` as people use it: heartbeats while the session is open, the watchdog
said out loud, telemetry flags by name, one field per line on request, no errors for the frame
cut by opening the port, history across sessions."""

import io
import os
import subprocess
import sys
from pathlib import Path

import pytest

from mobigrasp.link.messages import Link
from mobigrasp.link.registry import open_transport
from mobigrasp.mcu_sim.mcu_pty import PtyMcu
from mobigrasp.protocol import (
    FLAG_HANDSHAKE,
    FLAG_WATCHDOG,
    Ack,
    Heartbeat,
    HelloAck,
    Telemetry,
    encode_message,
)
from mobigrasp.tools.commands.console import ConsoleShell

ROOT = Path(__file__).resolve().parents[3]
SAFETY_S = 60


class _R:
    def __init__(self, msg):
        self.msg = msg


class FakeLink:
    """Sends are recorded; poll() hands out what the test queued."""

    def __init__(self):
        self.sent = []
        self.queue = []
        self.rx_frames = 0
        self.stats = {}

    def send(self, msg):
        self.sent.append(msg)
        if type(msg).__name__ == "Hello":
            self.queue += [Ack(len(self.sent)), HelloAck(1, "fake", 0)]
        return len(self.sent)

    def poll(self):
        out, self.queue = [_R(m) for m in self.queue], []
        self.rx_frames += len(out)
        return out

    def wait(self, timeout_s):
        return bool(self.queue)


def tel(t_us, flags, trips):
    return Telemetry(t_us, 0, 0, (1500,) * 6, (0xFFFF,) * 5, flags, 0, 0, 0, trips)


def test_heartbeats_go_out_once_the_session_is_open():
    link = FakeLink()
    out = io.StringIO()
    shell = ConsoleShell(link, reply_timeout_s=1.0, stdout=out, heartbeat_ms=100)
    shell.heartbeat_step(0.0)
    assert not any(isinstance(m, Heartbeat) for m in link.sent)  # no session yet
    shell.onecmd("hello")
    try:
        assert shell.session_open and "HELLO_ACK firmware=fake" in out.getvalue()
        for t in (10.0, 10.05, 10.1, 10.15, 10.2):
            shell.heartbeat_step(t)
        beats = [m for m in link.sent if isinstance(m, Heartbeat)]
        assert len(beats) == 3  # at 10.0, 10.1, 10.2
        assert beats[0].time_us == 10_000_000
    finally:
        shell.postloop()


def test_no_heartbeats_when_switched_off():
    link = FakeLink()
    shell = ConsoleShell(link, reply_timeout_s=1.0, stdout=io.StringIO(), heartbeat_ms=0)
    shell.onecmd("hello")
    try:
        for t in (1.0, 2.0, 3.0):
            shell.heartbeat_step(t)
        assert not any(isinstance(m, Heartbeat) for m in link.sent)
    finally:
        shell.postloop()


class HeartbeatReadsFirstLink(FakeLink):
    """Every reply arrives, and the heartbeat thread has its turn, between a command's send and
    its first poll: the thread reads the reply first (what a loaded machine makes likely)."""

    shell = None

    def send(self, msg):
        seq = super().send(msg)
        if msg.RELIABLE and type(msg).__name__ != "Hello":
            self.queue.append(Ack(seq))
        self.shell.heartbeat_step(0.0)
        return seq


def test_a_reply_read_by_the_heartbeat_thread_reaches_the_waiting_command():
    link = HeartbeatReadsFirstLink()
    out = io.StringIO()
    shell = ConsoleShell(link, reply_timeout_s=0.0, stdout=out, heartbeat_ms=0)
    link.shell = shell
    try:
        shell.onecmd("hello")
        shell.onecmd("gripper 1000")
    finally:
        shell.postloop()
    text = out.getvalue()
    assert "ACK seq=1\nHELLO_ACK firmware=fake" in text
    assert "ACK seq=2" in text
    assert "no reply" not in text


def test_watchdog_trip_and_clear_are_said():
    link = FakeLink()
    out = io.StringIO()
    shell = ConsoleShell(link, stdout=out, heartbeat_ms=0)
    link.queue = [tel(10_000, FLAG_WATCHDOG, 1)]  # before the session: not news
    shell.heartbeat_step(0.0)
    assert "watchdog" not in out.getvalue()
    shell.session_open = True
    link.queue = [tel(20_000, FLAG_HANDSHAKE, 0), tel(300_000, FLAG_HANDSHAKE | FLAG_WATCHDOG, 1),
                  tel(320_000, FLAG_HANDSHAKE | FLAG_WATCHDOG, 1), tel(340_000, FLAG_HANDSHAKE, 1)]
    shell.heartbeat_step(0.0)
    text = out.getvalue()
    assert text.count("watchdog tripped") == 1
    assert "watchdog tripped (t=300000 us, trips=1)" in text
    assert "watchdog cleared (t=340000 us)" in text
    # a trip between two frames (flag already gone again) is seen from the count
    link.queue = [tel(900_000, FLAG_HANDSHAKE, 2)]
    shell.heartbeat_step(0.1)
    assert out.getvalue().count("watchdog tripped") == 2


def test_telemetry_flags_by_name_and_watch_one_field_per_line():
    link = FakeLink()
    out = io.StringIO()
    shell = ConsoleShell(link, reply_timeout_s=0.0, stdout=out, heartbeat_ms=0)
    link.queue = [tel(20_000, FLAG_HANDSHAKE, 0)]
    shell.onecmd("telemetry")
    assert "flags=0x04 (HANDSHAKE)" in out.getvalue()
    link.queue = [tel(40_000, FLAG_HANDSHAKE | FLAG_WATCHDOG, 0), tel(60_000, FLAG_HANDSHAKE, 0)]
    shell.onecmd("telemetry --watch 2")
    lines = out.getvalue().splitlines()
    assert "  time_us         40000" in lines and "  time_us         60000" in lines
    assert "  flags           0x05 WATCHDOG|HANDSHAKE" in lines
    assert "  enc_left        0" in lines
    shell.onecmd("telemetry --watch zero")
    assert "usage: telemetry [--watch [N]]" in out.getvalue()


def test_the_frame_cut_by_opening_the_port_is_not_an_error():
    pty = PtyMcu()
    try:
        frame = encode_message(tel(0, 0, 0), 1)
        with Link(open_transport(pty.port)) as link:
            # opening flushed what was waiting; then the end of a frame whose start went out
            # before the port was opened arrives, then a whole one
            pty.transport.write(frame[len(frame) // 2:] + frame)
            shell = ConsoleShell(link, reply_timeout_s=SAFETY_S, stdout=io.StringIO(),
                                 heartbeat_ms=0)
            shell.onecmd("telemetry")
            raw = link.stats
            assert raw["parser_garbage_bytes"] > 0  # the parser did reject the cut frame
            st = shell.link_stats()
            assert all(st[f"parser_{k}"] == 0 for k in ("crc_errors", "truncated",
                                                        "cobs_errors", "garbage_bytes"))
            assert st["skipped_before_first_frame"] == raw["parser_garbage_bytes"]
            # a corrupt frame after the first whole one is counted as ever
            bad = bytearray(frame)
            bad[3] ^= 0x55
            pty.transport.write(bytes(bad))
            shell.onecmd("stats")
            assert shell.link_stats()["parser_garbage_bytes"] > 0
    finally:
        pty.close()


def run_console(port, home, script, *extra):
    env = dict(os.environ, HOME=str(home))
    return subprocess.run([sys.executable, "-m", "mobigrasp", "console", "--port", port, *extra],
                          input=script, capture_output=True, text=True, env=env, cwd=ROOT,
                          timeout=SAFETY_S)


def test_history_is_kept_across_sessions(tmp_path):
    pty = PtyMcu()
    try:
        first = run_console(pty.port, tmp_path, "params\nquit\n")
        assert first.returncode == 0, first.stderr
        hist = tmp_path / ".mobigrasp_history"
        assert "params" in hist.read_text().splitlines()
        second = run_console(pty.port, tmp_path, "stats\nquit\n")
        assert second.returncode == 0, second.stderr
        lines = hist.read_text().splitlines()
        assert lines.index("params") < lines.index("stats")
    finally:
        pty.close()


def test_history_file_that_is_a_directory_is_reported_not_raised(tmp_path):
    (tmp_path / ".mobigrasp_history").mkdir()
    pty = PtyMcu()
    try:
        res = run_console(pty.port, tmp_path, "quit\n")
    finally:
        pty.close()
    assert res.returncode == 0
    assert "Traceback" not in res.stderr and "cannot write history" in res.stderr


@pytest.mark.slow
def test_wheels_keep_turning_with_heartbeats_and_stop_without(tmp_path):
    """Against `mobigrasp mcu --speed 1`: 30 telemetry frames (0.6 s simulated) after `wheels`;
    with heartbeats the watchdog never trips, without them it does and the console says so."""
    script = "hello\nwheels 200 200\ntelemetry --watch 30\ntelemetry\nquit\n"
    texts = {}
    for beat in ("100", "0"):
        mcu = subprocess.Popen([sys.executable, "-m", "mobigrasp", "mcu", "--speed", "1"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               cwd=ROOT)
        res = None
        try:
            port = mcu.stdout.readline().strip()
            res = run_console(port, tmp_path, script, "--heartbeat-ms", beat,
                              "--reply-timeout", "5")
        finally:
            if res is None or res.returncode != 0:  # the MCU would wait for a host forever
                mcu.kill()
            mcu.communicate(timeout=SAFETY_S)  # it ends when the console closes the port
        assert res.returncode == 0, res.stderr
        texts[beat] = res.stdout
    assert "watchdog tripped" not in texts["100"]
    last = [ln for ln in texts["100"].splitlines() if ln.startswith("  enc_left")][-1]
    assert int(last.split()[1]) > 0  # still turning at the end
    assert "watchdog tripped" in texts["0"]
