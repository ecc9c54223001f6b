"""10,000 frames through a real pty between two processes: none lost, duplicated or reordered.

The child is ``python -m link.echo SLAVE`` (pyserial on the slave, as the host opens its port).
Independent of machine speed: a bounded window of frames in flight, ``wait_readable`` with a
generous safety limit, no sleeps.
"""

import subprocess
import sys

import mobigrasp.protocol as p
from mobigrasp.link import Link, open_transport
from mobigrasp.link.echo import READY_TEXT

N_FRAMES = 10_000
WINDOW = 64
SAFETY_S = 60.0


def test_ten_thousand_frames_over_a_real_pty_between_two_processes():
    master = open_transport("pty://")
    child = subprocess.Popen(
        [sys.executable, "-m", "mobigrasp.link.echo", master.slave_path],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )
    try:
        link = Link(master)
        ready = []
        while not ready:
            assert link.wait(SAFETY_S), "echo process never greeted"
            ready = link.poll()
        assert ready[0].msg == p.Log(0, READY_TEXT)

        received: list[int] = []
        sent = 0
        while len(received) < N_FRAMES:
            while sent < N_FRAMES and sent - len(received) < WINDOW:
                # Alternate message kinds so frame lengths (and COBS groups) vary.
                msg = p.Heartbeat(sent) if sent % 2 else p.SetWheels(sent % 1001, -(sent % 997))
                link.send_with_seq(msg, sent % 256)
                sent += 1
            assert link.wait(SAFETY_S), f"stalled after {len(received)} frames"
            for r in link.poll():
                i = len(received)
                assert r.seq == i % 256
                expect = p.Heartbeat(i) if i % 2 else p.SetWheels(i % 1001, -(i % 997))
                assert r.msg == expect, f"frame {i}: got {r.msg}"
                received.append(i)
        assert received == list(range(N_FRAMES))
        stats = link.stats
        assert stats["rx_frames"] == N_FRAMES + 1 and stats["tx_frames"] == N_FRAMES
        assert stats["parser_garbage_bytes"] == 0 and stats["decode_errors"] == 0
    finally:
        master.close()
    _, err = child.communicate(timeout=SAFETY_S)
    assert child.returncode == 0, err.decode()
    assert f"{N_FRAMES} frames echoed" in err.decode()
