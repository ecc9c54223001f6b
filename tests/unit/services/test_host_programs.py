"""The C host program in process (services/host_programs.CProgramClient over hostc/inproc/):
for the same GRANTs, MCU bytes and camera frames (in the GRANT's blob, as in process they
travel) it answers the DONEs, serial bytes and BYE of the Python host program, both running the
idle method (host/task/idle.py, hostc/task_idle.c)."""

from rig_fakes import BufferPort

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.hosts import InprocHost
from mobigrasp.drivers.lockstep import LockstepClient
from mobigrasp.host.app_factory import build_host_app
from mobigrasp.protocol import messages as m
from mobigrasp.services.host_programs import CProgramClient


def _mcu(t_us: int, until_us: int) -> list[tuple[int, bytes]]:
    """HELLO_ACK at 4 ms, telemetry every 10 ms (a reset at 405 ms), an ACK every 70 ms."""
    out = []
    for at in range(t_us - t_us % 1000, until_us, 1000):
        if not t_us <= at < until_us:
            continue
        if at == 4000:
            out.append((at, m.encode_message(m.HelloAck(1, "atmega128-fw"), 0)))
        if at % 10_000 == 5000:
            flags = m.FLAG_RESET if at == 405_000 else m.FLAG_HANDSHAKE
            out.append((at, m.encode_message(m.Telemetry(at, 0, 0, (1500,) * 6, (2500,) * 5,
                                                         flags, 0, 0, 0, 0), 1)))
        if at % 70_000 == 33_000:
            out.append((at, m.encode_message(m.Ack(at // 70_000), 2)))
    return out


def test_the_c_program_in_process_answers_as_the_python_host():
    py_port, c_port = BufferPort(), BufferPort()
    python = InprocHost(LockstepClient(build_host_app({"method": "idle"}), py_port))
    c = InprocHost(CProgramClient("idle", c_port))
    python.verify_elided = c.verify_elided = True  # every grant served, DONEs compared
    t = 0
    for k in range(160):  # 0.8 s in 5 ms quanta, one of 23 ms
        until = t + (23_000 if k == 50 else 5_000)
        chunks = _mcu(t, until)
        frames = tuple(ls.FrameBlob(at // 66_000, at - 3000, at, 320, 240, 3,
                                    bytes([at % 251]) * (320 * 240 * 3))
                       for at in range(t - t % 66_000 + 66_000, until, 66_000))
        grant = ls.Grant(t, until, tuple((a, len(b)) for a, b in chunks), frames)
        data = b"".join(b for _, b in chunks)
        py_port.rx += data
        c_port.rx += data
        assert c.exchange(grant) == python.exchange(grant), k
        assert c_port.tx == py_port.tx
        t = until
    assert py_port.tx  # HELLO and heartbeats at least
    want = python.finish(ls.End(t, "test over")).stats
    got = c.finish(ls.End(t, "test over")).stats
    for key in ("control_steps", "frames_received", "frames_idle", "mcu_resets_seen", "state"):
        assert got[key] == want[key], key
    assert got["frames_received"] >= 10 and got["mcu_resets_seen"] == 1
    for key in ("tx_frames", "rx_frames", "retransmits", "nacks", "crc_errors"):
        assert got["protocol"][key] == want["protocol"][key], key
