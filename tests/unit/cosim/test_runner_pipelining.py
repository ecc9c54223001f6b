"""Pipelined grants over the socket (tools/hosts.SocketHost, docs/cosim.md "Pipelining").

A grant that ends at or before the host's last ``quiet_until`` is answered at once with a
PendingDone; the real DONE is read later, checked against the promise, and the trace is the same
as when every grant is answered one by one.
"""

import sys

import pytest

from mobigrasp.cosim import handshake, hosts, session
from mobigrasp.cosim import lockstep as ls
from mobigrasp.services.run_job import RunOptions, execute

SAFETY_S = 60.0


def _host(script: str) -> hosts.SocketHost:
    return hosts.SocketHost([sys.executable, "-c", script, "--lockstep"],
                             accept_timeout_s=SAFETY_S)


# a "host" that promises quiet until 20 ms and answers every grant after reading it; the
# DONE of the grant ending at BREAK_US carries a write
_SCRIPT = """
import socket, sys
from mobigrasp.cosim import lockstep as ls
s = socket.socket(socket.AF_UNIX); s.connect(sys.argv[-1])
r, w = s.makefile("rb"), s.makefile("wb")
w.write(ls.encode(ls.Hello(host_id="fake"))); w.flush()
while True:
    msg = ls.read_message(r)
    if isinstance(msg, ls.End):
        w.write(ls.encode(ls.Bye(stats={"ok": 1}))); w.flush(); break
    writes = ((msg.start_us, 0),) if msg.until_us == BREAK_US else ()
    load = {"window_us": 500000, "windows": {}, "state": "S", "finished": False,
            "camera": True, "quiet_until": 20000}
    w.write(ls.encode(ls.Done(until_us=msg.until_us, writes=writes, load=load))); w.flush()
"""


def _grant(k: int, uart: bool = False) -> ls.Grant:
    # with a UART chunk the grant is sent even when its DONE is known (handshake.quiet_done); the
    # fake host above does not read the pty
    chunks = ((5000 * k, 1),) if uart else ()
    return ls.Grant(start_us=5000 * k, until_us=5000 * (k + 1), uart=chunks)


def test_quiet_grants_are_answered_ahead_and_read_in_order():
    host = _host(_SCRIPT.replace("BREAK_US", "-1"))
    try:
        first = host.exchange(_grant(0))  # nothing promised yet: answered one by one
        assert not isinstance(first, handshake.PendingDone) and first.until_us == 5000
        ahead = [host.exchange(_grant(k, uart=True)) for k in (1, 2, 3)]  # end <= 20 ms
        assert all(isinstance(d, handshake.PendingDone) for d in ahead)
        assert [d.load["state"] for d in ahead] == ["S"] * 3 and not any(d.writes for d in ahead)
        last = host.exchange(_grant(4))  # ends at 25 ms, past the promise: waits
        assert not isinstance(last, handshake.PendingDone)
        # reading the fifth DONE read the three before it, in order
        assert [handshake.resolved(d, block=False).until_us for d in ahead] == [10_000, 15_000,
                                                                               20_000]
        assert host.finish(ls.End(at_us=25_000, reason="t")).stats == {"ok": 1}
    finally:
        host.close()


def test_a_claim_becomes_a_promise_when_a_later_done_covers_it():
    # lag 1: the grant ending at 10 ms is sent before any DONE was read, so it is only a claim;
    # once the DONE ending at 5 ms (quiet until 20 ms) is read, the claim is a promise and the
    # rig completes that quantum without waiting for its own DONE
    host = _host(_SCRIPT.replace("BREAK_US", "-1"))
    try:
        claims = [host.submit(_grant(0)), host.submit(_grant(1, uart=True))]
        assert not any(c.promised for c in claims)
        first = handshake.needed(claims[0])
        assert not isinstance(first, handshake.PendingDone) and first.until_us == 5000
        second = handshake.needed(claims[1])
        assert isinstance(second, handshake.PendingDone) and second.promised
        assert second.load["state"] == "S" and not second.writes
        assert handshake.resolved(second).until_us == 10_000  # still read, in order, and checked
        assert host.finish(ls.End(at_us=10_000, reason="t")).stats == {"ok": 1}
    finally:
        host.close()


def test_a_broken_quiet_promise_is_an_error():
    host = _host(_SCRIPT.replace("BREAK_US", "15000"))
    try:
        host.exchange(_grant(0))
        pending = [host.exchange(_grant(k, uart=True)) for k in (1, 2)]
        assert all(isinstance(d, handshake.PendingDone) for d in pending)
        with pytest.raises(ls.LockstepError, match="broke its quiet_until promise .* 15000 us"):
            handshake.resolved(pending[1])
    finally:
        host.close()


def test_pipelined_pty_run_has_the_inproc_trace(tmp_path, monkeypatch):
    counts = {"pending": 0}
    needed = handshake.needed

    def counting(done):
        done = needed(done)
        counts["pending"] += isinstance(done, handshake.PendingDone)  # completed on a promise
        return done

    monkeypatch.setattr(session, "needed", counting)
    sha = {}
    for transport in ("pty", "inproc"):
        s, _ = execute(RunOptions(scenario="paper002-marker", transport=transport,
                                  out=tmp_path / transport, progress=False, plots=False,
                                  time_limit_s=1.5))
        assert s["status"] == "finished", s.get("error")
        sha[transport] = (s["trace_sha256"], s["trace_lines"])
    assert sha["pty"] == sha["inproc"]
    assert counts["pending"] > 100  # most 5 ms quanta of 1.5 s have no control tick


def test_inproc_passes_an_empty_done_as_the_codec_would(monkeypatch):
    from mobigrasp.drivers.lockstep import LockstepClient
    from mobigrasp.host.app_factory import build_host_app
    from mobigrasp.link.registry import inproc_pair
    from mobigrasp.services.run_job import host_config, resolve_scenario

    _, scenario = resolve_scenario("paper000-exp1")
    port, peer = inproc_pair("codec-skip")
    host = hosts.InprocHost(LockstepClient(build_host_app(host_config(scenario)), peer))
    skipped = 0
    for k in range(12):
        done = host.exchange(_grant(k))
        again = ls.decode(ls.encode(done))
        assert again == done and dict(again.load) == dict(done.load)
        skipped += not done.events and not done.load.get("windows")
    assert skipped >= 6
