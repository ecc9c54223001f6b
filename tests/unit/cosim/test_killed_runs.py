"""A run ended from outside: SIGTERM is handled like Ctrl-C, a SIGKILLed run's summary says how
far it got, and neither leaves shared memory or temporary folders behind for good
(cosim/run.py, cosim/leftovers.py; docs/cosim.md "Killed runs")."""

import json
import os
import re
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

from mobigrasp.cosim import leftovers

SAFETY_S = 120


def _start(out: Path) -> subprocess.Popen:
    # paced (--speed 2): after the progress line at 5.5 s the run has more than 5 s of wall time
    # left, however slow the machine, and a progress line at every update
    env = dict(os.environ, MOBIGRASP_PROGRESS_INTERVAL_S="0")
    return subprocess.Popen([sys.executable, "-m", "mobigrasp", "run", "paper000-exp1",
                             "--out", str(out), "--no-plots", "--time-limit-s", "60",
                             "--speed", "2"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)


def _wait_for_sim_time(proc: subprocess.Popen, t_s: float) -> float:
    """Read the progress lines on stderr (``run: T/60 s simulated ...``, tools/progress.py)
    until one shows simulated time ``t_s`` or more; that time (the process is waited on, not
    the clock)."""
    seen = []
    while True:
        line = proc.stderr.readline()
        assert line, f"the run ended before t = {t_s} s: {seen[-5:]}"
        seen.append(line.decode(errors="replace"))
        m = re.match(r"run: ([0-9.]+)/", seen[-1])
        if m and float(m.group(1)) >= t_s:
            return float(m.group(1))


def _leftovers_of(pid: int) -> list[str]:
    found = []
    for root in (tempfile.gettempdir(), "/dev/shm"):
        if os.path.isdir(root):
            found += [os.path.join(root, n) for n in os.listdir(root)
                      if re.match(rf"^mobigrasp-(frames|ls|run)-{pid}-", n)]
    return found


def test_sigterm_ends_a_run_like_ctrl_c(tmp_path):
    proc = _start(tmp_path / "run")
    try:
        _wait_for_sim_time(proc, 5.5)
        assert _leftovers_of(proc.pid)  # while it runs: its frame ring and folders exist
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=SAFETY_S)
    finally:
        proc.kill()
        proc.wait()
    assert proc.returncode == 130
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["status"] == "interrupted"
    assert summary["sim_time_s"] >= 5.0
    assert "Traceback" not in err.decode(errors="replace")
    assert _leftovers_of(proc.pid) == []


def test_a_sigkilled_run_says_how_far_it_got_and_the_next_start_sweeps_it(tmp_path):
    proc = _start(tmp_path / "run")
    try:
        reached_s = _wait_for_sim_time(proc, 5.5)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=SAFETY_S)
    finally:
        proc.kill()
        proc.wait()
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["status"] == "running"
    assert 5.0 <= summary["sim_time_s"] <= reached_s
    assert summary["pid"] == proc.pid
    left = _leftovers_of(proc.pid)
    assert left  # it could not remove its folders
    # the frame ring's name went once the host had mapped it: no 7 MB left in /dev/shm
    assert not any("mobigrasp-frames-" in p for p in left), left
    removed = leftovers.sweep()
    assert _leftovers_of(proc.pid) == []
    assert all(f"-{proc.pid}-" in p.name for p in removed if p.name.startswith("mobigrasp-"))


def test_sweep_removes_only_a_dead_owners_entries(tmp_path):
    done = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    dead = int(done.stdout)
    live = os.getpid()
    (tmp_path / f"mobigrasp-ls-{dead}-abc123").mkdir()
    (tmp_path / f"mobigrasp-run-{dead}-x_y9").mkdir()
    (tmp_path / f"mobigrasp-frames-{dead}-q1w2").write_bytes(b"\0" * 16)
    (tmp_path / f"mobigrasp-ls-{live}-abc123").mkdir()
    (tmp_path / f"mobigrasp-notes-{dead}-abc").mkdir()  # not a kind mobigrasp makes
    (tmp_path / f"mobigrasp-run-{dead}-file").write_text("a file where a folder would be")
    (tmp_path / "mobigrasp-ls-1x-abc").mkdir()  # no pid
    removed = {p.name for p in leftovers.sweep([tmp_path])}
    assert removed == {f"mobigrasp-ls-{dead}-abc123", f"mobigrasp-run-{dead}-x_y9",
                       f"mobigrasp-frames-{dead}-q1w2"}
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [f"mobigrasp-ls-{live}-abc123", f"mobigrasp-notes-{dead}-abc",
         f"mobigrasp-run-{dead}-file", "mobigrasp-ls-1x-abc"])


def test_prefix_names_the_kind_and_this_process():
    assert leftovers.prefix("frames") == f"mobigrasp-frames-{os.getpid()}-"
    try:
        leftovers.prefix("cache")
    except ValueError as exc:
        assert "cache" in str(exc)
    else:
        raise AssertionError("an unknown kind was accepted")
