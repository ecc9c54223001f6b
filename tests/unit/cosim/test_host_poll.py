"""The host polls its lockstep socket before sleeping when a run goes at full speed
(cosim.lockstep.SocketReader poll_s, ``mobigrasp host --poll-ms``, docs/cosim.md)."""

import socket
import subprocess
import sys

import pytest

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.hosts import HOST_POLL_MS, host_argv
from mobigrasp.services import run_job


@pytest.mark.parametrize("poll_s", [0.0, 0.05])
def test_polling_reader_reads_the_same_bytes(poll_s):
    a, b = socket.socketpair()
    try:
        msgs = [ls.Grant(start_us=5000 * i, until_us=5000 * (i + 1), uart=((5000 * i, 3),))
                for i in range(3)]
        a.sendall(b"".join(ls.encode(m) for m in msgs))
        reader = ls.SocketReader(b, poll_s=poll_s)
        assert [ls.read_message(reader) for _ in msgs] == msgs
        a.close()  # a closed peer ends the poll at once: the read says the stream ended
        with pytest.raises(ls.LockstepClosed):
            ls.read_message(reader)
    finally:
        b.close()


@pytest.mark.parametrize("bad", [-1.0, float("nan")])
def test_polling_reader_refuses_a_bad_time(bad):
    a, b = socket.socketpair()
    with a, b, pytest.raises(ValueError, match="poll_s"):
        ls.SocketReader(b, poll_s=bad)


def test_host_command_line_carries_the_poll_time():
    assert "--poll-ms" not in host_argv("/dev/pts/9", "cfg.json")
    argv = host_argv("/dev/pts/9", "cfg.json", HOST_POLL_MS)
    assert argv[argv.index("--poll-ms") + 1] == f"{HOST_POLL_MS:g}"


@pytest.mark.parametrize("value", ["-5", "nan", "abc", "20000"])
def test_host_refuses_a_bad_poll_time(value):
    out = subprocess.run([sys.executable, "-m", "mobigrasp", "host", "--port", "/dev/null",
                          "--lockstep", "/nonexistent.sock", "--poll-ms", value],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2 and "--poll-ms" in out.stderr


@pytest.mark.parametrize("speed, polls", [(None, True), (1.0, False)])
def test_run_polls_only_at_full_speed(monkeypatch, tmp_path, speed, polls):
    seen = []

    class Stop(Exception):
        pass

    def fake_socket_host(argv, connect=True, poll_ms=0.0):
        seen.append((argv, poll_ms))
        raise Stop

    monkeypatch.setattr("mobigrasp.cosim.run.SocketHost", fake_socket_host)
    with pytest.raises(Stop):
        run_job.execute(run_job.RunOptions(scenario="paper000-exp1", transport="pty",
                                           out=tmp_path, progress=False, plots=False,
                                           speed=speed))
    argv, rig_poll_ms = seen[0]
    assert ("--poll-ms" in argv) == polls  # the host for its grants
    assert rig_poll_ms == (HOST_POLL_MS if polls else 0.0)  # the rig for its DONEs


def test_rig_side_reader_polls_as_asked(monkeypatch):
    """SocketHost hands its poll time to the reader of the host's DONEs."""
    made = []

    class Reader:
        def __init__(self, sock, poll_s=0.0):
            made.append(poll_s)
            raise ConnectionError("stop here")

    from mobigrasp.cosim.hosts import SocketHost

    monkeypatch.setattr("mobigrasp.cosim.hosts.ls.SocketReader", Reader)
    host = SocketHost([sys.executable, "-c", "import socket, sys; "
                       "s = socket.socket(socket.AF_UNIX); s.connect(sys.argv[-1]); s.recv(1)"],
                      connect=False, poll_ms=HOST_POLL_MS)
    try:
        with pytest.raises(ConnectionError):
            host.connect()
    finally:
        host.proc.kill()
        host.proc.wait()
    assert made == [HOST_POLL_MS / 1000.0]


@pytest.mark.parametrize("bad", [-1.0, float("nan")])
def test_socket_host_refuses_a_bad_poll_time(bad):
    from mobigrasp.cosim.hosts import SocketHost

    with pytest.raises(ValueError, match="poll_ms"):
        SocketHost([sys.executable, "-c", "pass"], connect=False, poll_ms=bad)
