"""Fewer lockstep messages (cosim/hosts.py, docs/cosim.md "Fewer messages").

A grant whose DONE is known (no UART bytes, no frames, inside the host's quiet_until, no load
window ending) is not sent at all; other promised grants without frames wait and leave in one
write with the next grant the rig needs an answer to; the host answers a batch in one write.
None of it may change a DONE or the trace: ``verify_elided`` sends the elided grants anyway and
compares the host's real DONEs with the predicted ones.
"""

import sys

import pytest

from mobigrasp.cosim import handshake, hosts
from mobigrasp.cosim import lockstep as ls
from mobigrasp.services.run_job import RunOptions, execute

LOAD = {"window_us": 500_000, "windows": {}, "state": "APPROACH", "finished": False,
        "camera": True, "quiet_until": 20_000}


def _grant(start_us: int, uart=(), frames=()) -> ls.Grant:
    return ls.Grant(start_us=start_us, until_us=start_us + 5000, uart=uart, frames=frames)


def test_quiet_done_is_the_done_of_an_idle_quiet_quantum():
    done = handshake.quiet_done(_grant(10_000), LOAD)
    assert done == ls.Done(until_us=15_000, writes=(), events=(), load=dict(LOAD))


@pytest.mark.parametrize("grant, load", [
    (_grant(10_000, uart=((10_000, 4),)), LOAD),  # bytes for the host: it parses them
    (_grant(10_000, frames=(ls.FrameBlob(1, 0, 10_000, 0, 0, 0, b""),)), LOAD),  # a frame slot
    (_grant(20_000), LOAD),  # ends past quiet_until: a control tick in it
    (_grant(495_000), {**LOAD, "quiet_until": 600_000}),  # ends load window 0: reports it
    (_grant(10_000), {}),  # no DONE read yet
    (_grant(10_000), {**LOAD, "quiet_until": None}),
    (_grant(10_000), {**LOAD, "window_us": 0}),
])
def test_quiet_done_declines_what_it_cannot_tell(grant, load):
    assert handshake.quiet_done(grant, load) is None


# a fake host that counts the grants and the socket reads it got, answers each with a quiet
# DONE (quiet until 20 ms) and, with the lead's reader, one write per batch
_SCRIPT = """
import socket, sys
from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.frame_ring import FrameRingReader
s = socket.socket(socket.AF_UNIX); s.connect(sys.argv[-1])
r, w = ls.SocketReader(s), s.makefile("wb")
w.write(ls.encode(ls.Hello(host_id="fake"))); w.flush()
seen, out = [], bytearray()
while True:
    msg = ls.read_message(r, FrameRingReader())
    if isinstance(msg, ls.End):
        w.write(out + ls.encode(ls.Bye(stats={"seen": seen}))); w.flush(); break
    seen.append(msg.until_us)
    load = {"window_us": 500000, "windows": {}, "state": "S", "finished": False,
            "camera": True, "quiet_until": 20000}
    out += ls.encode(ls.Done(until_us=msg.until_us, writes=(), load=load))
    if not r.buffered:
        w.write(out); w.flush(); out.clear()
"""


def _host() -> hosts.SocketHost:
    return hosts.SocketHost([sys.executable, "-c", _SCRIPT, "--lockstep"],
                             accept_timeout_s=60.0)


def test_idle_grants_are_not_sent_and_the_rest_leave_in_batches():
    host = _host()
    try:
        first = handshake.needed(host.submit(_grant(0)))  # no DONE read yet: sent, waited for
        assert first.until_us == 5000 and host.messages_sent == 1
        idle = host.submit(_grant(5000))  # known: never sent
        with_bytes = host.submit(_grant(10_000, uart=((10_000, 2),)))  # promised: held back
        assert idle.promised and with_bytes.promised and host.messages_sent == 1
        tick = host.submit(_grant(20_000))  # past the promise: goes now, with the one held
        assert host.messages_sent == 2
        assert handshake.needed(tick).until_us == 25_000
        assert handshake.resolved(idle) == handshake.quiet_done(_grant(5000), host._last_load)
        assert handshake.resolved(with_bytes).until_us == 15_000
        bye = host.finish(ls.End(at_us=25_000, reason="t"))
        assert bye.stats["seen"] == [5000, 15_000, 25_000]  # the idle grant never went
        assert host.elided == 1
    finally:
        host.close()


def test_only_the_grant_the_rig_will_wait_for_is_wanted_early():
    host = _host()
    try:
        handshake.needed(host.submit(_grant(0)))  # DONE read: quiet until 20 ms
        assert host.early_wanted(20_000)  # the control tick's grant: its DONE will be waited for
        assert not host.early_wanted(25_000)  # after it: elided or batched once that DONE is read
        host.finish(ls.End(at_us=5000, reason="t"))
    finally:
        host.close()


def test_a_grant_with_a_frame_is_not_held_back():
    host = _host()
    try:
        handshake.needed(host.submit(_grant(0)))
        host.submit(_grant(5000, uart=((5000, 1),)))
        assert host.messages_sent == 1
        frame = ls.FrameBlob(seq=0, capture_us=0, arrival_us=10_000, width=2, height=1,
                             channels=3, pixels=bytes(6))
        host.submit(_grant(10_000, frames=(frame,)))  # vision should start early: sent now
        assert host.messages_sent == 2
        assert host.finish(ls.End(at_us=15_000, reason="t")).stats["seen"] == [5000, 10_000,
                                                                               15_000]
    finally:
        host.close()


@pytest.mark.parametrize("transport", ["pty", "inproc"])
def test_elided_grants_would_have_got_exactly_the_predicted_done(transport, tmp_path,
                                                                   monkeypatch):
    """On a real run every elided grant is served anyway and its DONE compared (a mismatch
    raises LockstepError and the run crashes); the trace is the one of the plain run."""
    checked = []
    check = hosts.check_elided

    def counting(predicted, real):
        check(predicted, real)
        checked.append(real.until_us)

    monkeypatch.setattr(hosts, "check_elided", counting)
    sha = {}
    for verify in (True, False):
        monkeypatch.setattr(hosts.SocketHost, "verify_elided", verify)
        monkeypatch.setattr(hosts.InprocHost, "verify_elided", verify)
        s, _ = execute(RunOptions(scenario="paper000-exp1", transport=transport,
                                  out=tmp_path / str(verify), progress=False, plots=False,
                                  time_limit_s=3.0))
        assert s["status"] == "finished", s.get("error")
        sha[verify] = s["trace_sha256"]
    assert sha[True] == sha[False]
    # of the 600 quanta of 3 s, about 100 (pty: the grant after a control tick's often goes
    # before the tick's DONE is read, Rig.grants_due) to 200 (in process) are idle and quiet
    assert len(checked) > 60


def test_socket_reader_reads_exactly_and_tells_what_it_holds():
    import socket

    a, b = socket.socketpair()
    try:
        reader = ls.SocketReader(b, chunk=64)
        a.sendall(ls.encode(ls.End(at_us=1, reason="x")) + ls.encode(ls.End(at_us=2, reason="y")))
        assert ls.read_message(reader) == ls.End(1, "x")
        assert reader.buffered > 0  # the second message came in the same read
        assert ls.read_message(reader) == ls.End(2, "y") and reader.buffered == 0
        a.sendall(ls.encode(ls.End(at_us=3, reason="z"))[:5])
        a.close()
        with pytest.raises(ls.LockstepClosed):
            ls.read_message(reader)  # the peer went away mid-message
    finally:
        b.close()
