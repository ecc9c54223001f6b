"""``mobigrasp link-demo [--count N]``: frames over a real pty to a second process and back.

Opens ``pty://``, prints the slave path, starts ``python -m link.echo SLAVE`` (which opens the
slave with pyserial, as the host opens its serial port), sends N HEARTBEAT / SET_WHEELS messages
one at a time and prints how many came back and the wall-clock round-trip times. A tool: the
wall clock is allowed here, never under protocol/, host/ or the firmware.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time

# Submodule imports: they also work when an editable install maps these packages as namespaces.
from mobigrasp.link.base import LinkClosed
from mobigrasp.link.echo import READY_TEXT
from mobigrasp.link.messages import Link
from mobigrasp.link.registry import open_transport
from mobigrasp.mcu_sim import checks
from mobigrasp.protocol import messages as p

REPLY_TIMEOUT_S = 5.0  # a safety limit for a lost frame, not a performance expectation


def _percentile(sorted_values: list[float], q: float) -> float:
    if not sorted_values:
        return float("nan")
    k = min(len(sorted_values) - 1, max(0, round(q * (len(sorted_values) - 1))))
    return sorted_values[k]


def run_link_demo(count: int, out=print) -> dict:
    """Run the demo; returns the figures it printed (count, lost, rtt_ms_p50/p95/max)."""
    if count < 1:
        raise ValueError(f"--count must be >= 1, got {count}")
    master = open_transport("pty://")
    out(f"pty slave: {master.slave_path}")
    child = subprocess.Popen([sys.executable, "-m", "mobigrasp.link.echo", master.slave_path],
                             stderr=subprocess.PIPE)
    link = Link(master)
    rtts_ms: list[float] = []
    lost = 0
    try:
        greeting = []
        deadline = time.monotonic() + 30.0
        while not any(r.msg == p.Log(0, READY_TEXT) for r in greeting):
            if time.monotonic() > deadline:
                raise RuntimeError("the echo process did not open the pty slave within 30 s")
            link.wait(1.0)
            greeting += link.poll()
        out(f"echo process {child.pid} opened the slave; sending {count} messages")
        for i in range(count):
            msg = p.Heartbeat(i) if i % 2 == 0 else p.SetWheels(i % 1000, -(i % 1000))
            seq = i & 0xFF
            t0 = time.perf_counter()
            link.send_with_seq(msg, seq)
            got = False
            while not got and time.perf_counter() - t0 < REPLY_TIMEOUT_S:
                link.wait(REPLY_TIMEOUT_S)
                got = any(r.seq == seq and r.msg == msg for r in link.poll())
            if got:
                rtts_ms.append((time.perf_counter() - t0) * 1e3)
            else:
                lost += 1
    except LinkClosed as exc:
        out(f"link closed: {exc}")
        lost = count - len(rtts_ms)
    finally:
        master.close()
        try:
            _, err = child.communicate(timeout=30.0)
            out(f"echo process exit {child.returncode}: {err.decode(errors='replace').strip()}")
        except subprocess.TimeoutExpired:
            child.kill()
            child.communicate()
            out("echo process did not exit within 30 s and was killed")
    rtts_ms.sort()
    result = {
        "count": count,
        "received": len(rtts_ms),
        "lost": lost,
        "rtt_ms_p50": _percentile(rtts_ms, 0.50),
        "rtt_ms_p95": _percentile(rtts_ms, 0.95),
        "rtt_ms_max": rtts_ms[-1] if rtts_ms else float("nan"),
        "tx_bytes": link.stats["tx_bytes"],
        "rx_bytes": link.stats["rx_bytes"],
    }
    out(f"sent {count}, received {result['received']}, lost {lost}")
    out(f"round trip (wall clock): p50 {result['rtt_ms_p50']:.3f} ms, "
        f"p95 {result['rtt_ms_p95']:.3f} ms, max {result['rtt_ms_max']:.3f} ms")
    out(f"bytes: {result['tx_bytes']} out, {result['rx_bytes']} in "
        f"(a pty has no baud rate; on a 115200 8N1 line one {len(link.last_wire)}-byte frame "
        f"takes {len(link.last_wire) * 10 / 115.2:.3f} ms each way)")
    return result


def _main(args: argparse.Namespace) -> int:
    result = run_link_demo(args.count)
    return 0 if result["lost"] == 0 else 1


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``link-demo``."""
    parser = sub.add_parser("link-demo", help="echo frames over a real pty through a 2nd process")
    parser.add_argument("--count", type=checks.arg_int(1, 1_000_000), default=300,
                        help="messages to send, 1..1000000 (default 300)")
    parser.set_defaults(func=_main)
