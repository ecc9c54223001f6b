"""A run ended from outside: SIGTERM is handled like Ctrl-C, a SIGKILLed run's summary says how
far it got, and neither leaves shared memory or temporary folders behind for good
(cosim/run.py, cosim/leftovers.py; docs/cosim.md "Killed runs")."""

import json
import math
import os
import re
import signal
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from mobigrasp.cosim import leftovers
from mobigrasp.services.mcap_out import read_messages

SAFETY_S = 120


@pytest.fixture
def run_tmp() -> Iterator[Path]:
    """A temporary folder of the run's own (and so a ledger of its own: a run started by another
    test at the same time sweeps the leftovers of dead runs in the shared one), short enough for
    the lockstep socket's path."""
    with tempfile.TemporaryDirectory(prefix="mg-") as tmp:
        yield Path(tmp)


def _start(out: Path, command: str = "run", tmp: Path | None = None) -> subprocess.Popen:
    # paced (--speed 2): after the progress line at 5.5 s the run has more than 5 s of wall time
    # left, however slow the machine, and a progress line at every update
    env = dict(os.environ, MOBIGRASP_PROGRESS_INTERVAL_S="0")
    if tmp is not None:  # its own temporary folder (run_tmp)
        env["TMPDIR"] = str(tmp)
    # sim: its clock runs at once, no host waited for (stdin here is not a terminal)
    extra = ["--no-wait-host"] if command == "sim" else []
    return subprocess.Popen([sys.executable, "-m", "mobigrasp", command, "paper000-exp1",
                             "--out", str(out), "--no-plots", "--time-limit-s", "60",
                             "--speed", "2", *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)


@contextmanager
def running(out: Path, command: str = "run", tmp: Path | None = None
            ) -> Iterator[subprocess.Popen]:
    """:func:`_start`, the process killed at the end whatever happened."""
    proc = _start(out, command, tmp)
    try:
        yield proc
    finally:
        proc.kill()
        proc.wait()


def _assert_jsonl_lost_at_most_its_last_line(path: Path) -> int:
    lines = path.read_text().split("\n")
    whole = lines[:-1]  # the text after the last newline is the one line a kill may tear
    for line in whole:
        json.loads(line)
    return len(whole)


def _wait_for_sim_time(proc: subprocess.Popen, t_s: float) -> float:
    """Read the progress lines on stderr (``run: T/60 s simulated ...``, tools/progress.py)
    until one shows simulated time ``t_s`` or more; that time (the process is waited on, not
    the clock)."""
    seen = []
    while True:
        line = proc.stderr.readline()
        assert line, f"the run ended before t = {t_s} s: {seen[-5:]}"
        seen.append(line.decode(errors="replace"))
        m = re.match(r"(?:run|sim [^:]+): ([0-9.]+)/", seen[-1])
        if m and float(m.group(1)) >= t_s:
            return float(m.group(1))


def _leftovers_of(pid: int, tmp: Path) -> list[str]:
    """The frame ring and folders run ``pid`` (temporary folder ``tmp``) has now."""
    found = []
    for root in (str(tmp), "/dev/shm"):
        if os.path.isdir(root):
            found += [os.path.join(root, n) for n in os.listdir(root)
                      if re.match(rf"^mobigrasp-(frames|ls|run)-{pid}-", n)]
    return found


def test_sigterm_ends_a_run_like_ctrl_c(tmp_path, run_tmp):
    proc = _start(tmp_path / "run", tmp=run_tmp)
    try:
        _wait_for_sim_time(proc, 5.5)
        # while it runs: its frame ring and folders exist
        assert _leftovers_of(proc.pid, run_tmp)
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
    assert _leftovers_of(proc.pid, run_tmp) == []


def _killed_at_5_5_s(out: Path, tmp: Path, command: str) -> tuple[subprocess.Popen, float]:
    """``command`` SIGKILLed once past 5.5 s simulated; (its process, the time it reached),
    after checking what it left says so: a running summary, a trace torn at most at its end."""
    with running(out, command, tmp) as proc:
        reached_s = _wait_for_sim_time(proc, 5.5)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=SAFETY_S)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "running" and summary["pid"] == proc.pid
    assert 5.0 <= summary["sim_time_s"] <= reached_s
    assert _assert_jsonl_lost_at_most_its_last_line(out / "trace.jsonl") > 100
    return proc, reached_s


def test_a_sigkilled_run_says_how_far_it_got_and_the_next_start_sweeps_it(tmp_path, run_tmp):
    proc, reached_s = _killed_at_5_5_s(tmp_path / "run", run_tmp, "run")
    # trace.mcap was written as the run went, a chunk per simulated second, each on the disk
    # before the run went past it: read back, it holds the camera frames, the trace topics and
    # the telemetry up to the last whole second the run reached (reached_s: the progress line
    # read before the kill, at most the kill's; rounded to 10 ms), so at most the last second
    # is lost; the truth topics are sampled every 0.1 s
    got = read_messages(tmp_path / "run" / "trace.mcap")
    last_s = {topic: max(t for tp, t, _ in got if tp == topic) / 1e9
              for topic in ("/camera/image", "/tf", "/joints", "/mcu/encoders")}
    whole_s = math.floor(reached_s - 0.01)
    assert whole_s >= 5
    assert last_s["/camera/image"] >= whole_s, (reached_s, last_s)
    assert all(t >= whole_s - 0.1 for t in last_s.values()), (reached_s, last_s)
    left = _leftovers_of(proc.pid, run_tmp)
    assert left  # it could not remove its folders
    # the frame ring's name went once the host had mapped it: no 7 MB left in /dev/shm
    assert not any("mobigrasp-frames-" in p for p in left), left
    removed = leftovers.sweep(run_tmp)
    assert _leftovers_of(proc.pid, run_tmp) == []
    assert all(f"-{proc.pid}-" in p.name for p in removed if p.name.startswith("mobigrasp-"))


def test_a_sigkilled_sim_session_says_it_did_not_finish(tmp_path, run_tmp):
    _killed_at_5_5_s(tmp_path / "session", run_tmp, "sim")


_CHILD = """
import os, sys
from mobigrasp.cosim import leftovers
book = sys.argv[1]
run = leftovers.temp_dir("run", ledger=book)
ls = leftovers.temp_dir("ls", ledger=book)
fd, ring = leftovers.temp_file("frames", book, ledger=book)
moved = leftovers.temp_dir("run", ledger=book)
open(os.path.join(run.name, "host.json"), "w").write("{}")
print(run.name, ls.name, ring, moved.name, flush=True)
os._exit(0)  # as SIGKILL would: nothing cleaned up
"""


def test_sweep_removes_only_what_a_dead_owner_recorded(tmp_path):
    done = subprocess.run([sys.executable, "-c", _CHILD, str(tmp_path)], capture_output=True,
                          text=True, check=True, env=dict(os.environ, TMPDIR=str(tmp_path)))
    run, ls, ring, moved = done.stdout.split()
    dead = int(Path(run).name.split("-")[2])
    # the recorded folder was replaced by someone else's of the same name: not the same inode
    for p in Path(moved).iterdir():
        p.unlink()
    Path(moved).rmdir()
    Path(moved).mkdir()
    (Path(moved) / "notes.txt").write_text("theirs")
    # names of the same pattern, with the dead pid, that nobody recorded
    thesis = tmp_path / f"mobigrasp-run-{dead}-thesis"
    thesis.mkdir()
    (thesis / "chapter1.tex").write_text("years of work")
    (tmp_path / f"mobigrasp-frames-{dead}-q1w2").write_bytes(b"\0" * 16)
    # a live owner's record is kept
    mine = leftovers.temp_dir("ls", ledger=tmp_path)
    removed = {str(p) for p in leftovers.sweep(tmp_path)}
    assert removed == {run, ls, ring}
    assert (thesis / "chapter1.tex").read_text() == "years of work"
    assert (tmp_path / f"mobigrasp-frames-{dead}-q1w2").exists()
    assert (Path(moved) / "notes.txt").read_text() == "theirs"
    assert Path(mine.name).is_dir()
    mine.cleanup()
    assert not Path(mine.name).exists()
    # the records of the dead owner are gone: a second sweep touches nothing
    assert leftovers.sweep(tmp_path) == []


def test_prefix_names_the_kind_and_this_process():
    assert leftovers.prefix("frames") == f"mobigrasp-frames-{os.getpid()}-"
    try:
        leftovers.prefix("cache")
    except ValueError as exc:
        assert "cache" in str(exc)
    else:
        raise AssertionError("an unknown kind was accepted")
