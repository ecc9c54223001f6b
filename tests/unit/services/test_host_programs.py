"""The C host program in process (services/host_programs.CProgramClient over hostc/inproc/):
for the same GRANTs, MCU bytes and camera frames (in the GRANT's blob, as in process they
travel) it answers the DONEs, serial bytes and BYE of the Python host program, both running the
idle method (host/task/idle.py, hostc/task_idle.c)."""

from rig_fakes import BufferPort, scripted_grants

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.hosts import InprocHost
from mobigrasp.drivers.lockstep import LockstepClient
from mobigrasp.host.app_factory import build_host_app
from mobigrasp.services.host_programs import CProgramClient


def test_the_c_program_in_process_answers_as_the_python_host():
    py_port, c_port = BufferPort(), BufferPort()
    python = InprocHost(LockstepClient(build_host_app({"method": "idle"}), py_port))
    c = InprocHost(CProgramClient({"method": "idle"}, c_port))
    python.verify_elided = c.verify_elided = True  # every grant served, DONEs compared
    for k, (grant, data) in enumerate(scripted_grants(320, 240)):  # frames of the camera's size
        py_port.rx += data
        c_port.rx += data
        assert c.exchange(grant) == python.exchange(grant), k
        assert c_port.tx == py_port.tx
    t = grant.until_us
    assert py_port.tx  # HELLO and heartbeats at least
    want = python.finish(ls.End(t, "test over")).stats
    got = c.finish(ls.End(t, "test over")).stats
    for key in ("control_steps", "frames_received", "frames_idle", "mcu_resets_seen", "state"):
        assert got[key] == want[key], key
    assert got["frames_received"] >= 10 and got["mcu_resets_seen"] == 1
    for key in ("tx_frames", "rx_frames", "retransmits", "nacks", "crc_errors"):
        assert got["protocol"][key] == want["protocol"][key], key
