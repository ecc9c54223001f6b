"""Issue 9: when one side of the link vanishes mid-run, the other side ends at once with a clear
message and a non-zero exit code, and never with a traceback.

Real processes on a real pty; the only waits are blocking reads and process exits with generous
safety limits (nothing asserts on speed).
"""

import contextlib
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.hosts import SocketHost
from mobigrasp.link.registry import open_transport

ROOT = Path(__file__).resolve().parents[3]
SAFETY_S = 60


@contextlib.contextmanager
def _cli(*args: str):
    """``mobigrasp ARGS`` as a child process, killed at the end if it is still there."""
    proc = subprocess.Popen([sys.executable, "-m", "mobigrasp.tools.cli", *args], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        yield proc
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(SAFETY_S)


def test_lockstep_host_ends_cleanly_when_the_simulator_vanishes(tmp_path):
    pty = open_transport("pty://")
    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    path = str(tmp_path / "ls.sock")
    server.bind(path)
    server.listen(1)
    server.settimeout(SAFETY_S)
    with _cli("host", "--port", pty.slave_path, "--method", "000", "--lockstep", path) as proc:
        conn, _ = server.accept()
        conn.settimeout(SAFETY_S)
        rfile, wfile = conn.makefile("rb"), conn.makefile("wb")
        assert isinstance(ls.read_message(rfile), ls.Hello)
        wfile.write(ls.encode(ls.Grant(start_us=0, until_us=5000)))
        wfile.flush()
        done = ls.read_message(rfile)
        assert isinstance(done, ls.Done) and done.until_us == 5000
        for f in (rfile, wfile, conn):  # the simulator dies: its socket and pty go away
            f.close()
        pty.close()
        _, err = proc.communicate(timeout=SAFETY_S)
    server.close()
    assert proc.returncode == 1
    assert "the simulator went away mid-run at t = 0.005 s simulated" in err
    assert "Traceback" not in err


def test_the_rig_names_a_host_process_that_died(tmp_path):
    # a "host" that says HELLO and dies before serving its first grant
    script = ("import socket,sys; from mobigrasp.cosim import lockstep as ls; "
              "s=socket.socket(socket.AF_UNIX); s.connect(sys.argv[-1]); "
              "s.sendall(ls.encode(ls.Hello(host_id='dying'))); sys.exit(7)")
    host = SocketHost([sys.executable, "-c", script, "--lockstep"], accept_timeout_s=SAFETY_S)
    try:
        with pytest.raises(ls.LockstepClosed, match=r"host process vanished at t = 0\.010 s "
                                                     r"simulated \(it exited with code 7"):
            host.exchange(ls.Grant(start_us=10_000, until_us=15_000))
    finally:
        host.close()


def test_free_running_host_ends_when_the_mcu_vanishes():
    from mobigrasp.mcu_sim.mcu_pty import PtyMcu

    mcu = PtyMcu(record=False)
    with _cli("host", "--port", mcu.port, "--method", "000") as proc:
        first = proc.stderr.readline()  # the host has opened the port and is running
        assert f"host on {mcu.port}" in first
        mcu.close()
        _, err = proc.communicate(timeout=SAFETY_S)
    assert proc.returncode == 1
    assert f"the MCU side closed the port {mcu.port}" in err
    assert "Traceback" not in err


def test_standalone_mcu_exits_nonzero_when_the_host_vanishes():
    with _cli("mcu", "--speed", "1", "--duration", "120") as proc:
        port = proc.stdout.readline().strip()
        host_end = open_transport(port)
        host_end.write(b"\x00")  # opened and used, then gone, as a crashed host
        host_end.close()
        _, err = proc.communicate(timeout=SAFETY_S)
    assert proc.returncode == 1
    assert "the host closed the port" in err
