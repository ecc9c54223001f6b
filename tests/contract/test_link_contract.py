"""One contract suite, run against every transport backend: in-process pair, a real pty
(master in this process, slave opened with pyserial), and pyserial's ``loop://``.

No sleeps: waiting is ``wait_readable`` with generous safety limits only.
"""

import threading

import pytest

import mobigrasp.protocol as p
from mobigrasp.link import Link, LinkClosed, inproc_pair, open_transport

SAFETY_S = 30.0


class Pair:
    def __init__(self, name, a, b, has_peer, has_fd):
        self.name, self.a, self.b = name, a, b
        self.has_peer, self.has_fd = has_peer, has_fd

    def close(self):
        for t in (self.a, self.b):
            t.close()


def _make(kind):
    if kind == "inproc":
        a, b = inproc_pair("contract")
        return Pair(kind, a, b, has_peer=True, has_fd=False)
    if kind == "inproc-url":
        a = open_transport("inproc://contract-url")
        b = open_transport("inproc://contract-url")
        return Pair(kind, a, b, has_peer=True, has_fd=False)
    if kind == "pty":
        master = open_transport("pty://")
        slave = open_transport(master.slave_path)
        return Pair(kind, master, slave, has_peer=True, has_fd=True)
    if kind == "loop":
        t = open_transport("loop://")
        return Pair(kind, t, t, has_peer=False, has_fd=False)
    raise KeyError(kind)


@pytest.fixture(params=["inproc", "inproc-url", "pty", "loop"])
def pair(request):
    pr = _make(request.param)
    yield pr
    pr.close()


def read_exactly(t, n):
    out = bytearray()
    while len(out) < n:
        assert t.wait_readable(SAFETY_S), f"nothing after {len(out)} of {n} bytes"
        out += t.read()
    return bytes(out)


def test_round_trip_both_directions_all_byte_values(pair):
    data = bytes(range(256)) * 3  # includes \r \n ^C ^D XON XOFF: raw mode must pass them
    pair.a.write(data)
    assert read_exactly(pair.b, len(data)) == data
    pair.b.write(data[::-1])
    assert read_exactly(pair.a, len(data)) == data[::-1]


def test_read_is_non_blocking_and_empty_when_idle(pair):
    assert pair.b.read() == b""
    assert pair.b.wait_readable(0.0) is False
    pair.a.write(b"x")
    assert pair.b.wait_readable(SAFETY_S) is True
    assert read_exactly(pair.b, 1) == b"x"


def test_fileno(pair):
    fd = pair.a.fileno()
    if pair.has_fd:
        assert isinstance(fd, int) and fd >= 0
    else:
        assert fd is None


def test_link_messages_in_any_chunking_and_stats(pair):
    tx, rx = Link(pair.a), Link(pair.b)
    msgs = [p.Heartbeat(i) for i in range(50)] + [
        p.SetServos(1, (0, 10, -20, 30, -40, 50), 100), p.Log(7, "hello"), p.Stop(),
        p.Telemetry(1, -2, 3, (1500,) * 6, (p.SONAR_NO_ECHO,) * 5, p.FLAG_HANDSHAKE, 0, 0, 0, 0),
    ]
    seqs = [tx.send(m) for m in msgs]
    assert seqs == list(range(len(msgs)))
    got = []
    while len(got) < len(msgs):
        assert rx.wait(SAFETY_S)
        got += rx.poll()
    assert [r.msg for r in got] == msgs and [r.seq for r in got] == seqs
    st_tx, st_rx = tx.stats, rx.stats
    assert st_tx["tx_frames"] == len(msgs) == st_rx["rx_frames"]
    assert st_tx["tx_bytes"] == st_rx["rx_bytes"] == sum(
        len(p.encode_message(m, s)) for m, s in zip(msgs, seqs, strict=True))
    assert st_rx["parser_frames_ok"] == len(msgs) and st_rx["parser_garbage_bytes"] == 0
    assert st_rx["decode_errors"] == 0


def test_large_write_while_peer_reads(pair):
    data = bytes(i * 7 % 251 + 1 for i in range(64_000))  # 3x what a pty master buffers
    writer = threading.Thread(target=pair.a.write, args=(data,))
    writer.start()
    try:
        assert read_exactly(pair.b, len(data)) == data
    finally:
        writer.join(SAFETY_S)
    assert not writer.is_alive()


def test_own_close_makes_read_and_write_raise(pair):
    pair.a.close()
    pair.a.close()  # idempotent
    assert pair.a.closed
    with pytest.raises(LinkClosed):
        pair.a.read()
    with pytest.raises(LinkClosed):
        pair.a.write(b"x")


def test_context_manager_closes():
    with _make("pty").a as t:
        assert not t.closed
    assert t.closed


def _wait_closed(t):
    for _ in range(1000):
        t.wait_readable(SAFETY_S)
        try:
            t.read()
        except LinkClosed:
            return True
    return False


@pytest.mark.parametrize("kind", ["inproc", "pty"])
@pytest.mark.parametrize("who_leaves", ["a", "b"])
def test_peer_vanishing_raises_link_closed(kind, who_leaves):
    pr = _make(kind)
    try:
        pr.b.write(b"hi")  # the peer has spoken: a pty master now lets go of its slave copy
        assert read_exactly(pr.a, 2) == b"hi"
        leaving, staying = (pr.a, pr.b) if who_leaves == "a" else (pr.b, pr.a)
        leaving.write(b"last words")
        assert read_exactly(staying, 10) == b"last words"
        leaving.close()
        assert _wait_closed(staying)
    finally:
        pr.close()


def test_pty_master_before_any_peer_reads_empty():
    master = open_transport("pty://")
    try:
        assert master.slave_path.startswith("/dev/")
        assert master.read() == b""
        master.write(b"queued")  # accepted even though nobody has opened the slave yet
    finally:
        master.close()


def test_pty_drop_unread_never_blocks_before_a_peer_and_keeps_the_newest_bytes():
    master = open_transport("pty://?drop_unread=1")
    try:
        assert master.drop_unread
        for i in range(200):  # 200 KB: ten times what the pty buffers
            master.write(bytes([i % 255 + 1]) * 1024)
        assert master.unread_flushes >= 5
        slave = open_transport(master.slave_path)  # pyserial flushes stale input on open
        master.write(b"fresh")
        assert read_exactly(slave, 5) == b"fresh"
        slave.write(b"!")
        assert read_exactly(master, 1) == b"!"
        slave.close()
    finally:
        master.close()


def test_pty_url_options_checked():
    with pytest.raises(ValueError, match="unknown pty URL option"):
        open_transport("pty://?speed=9")
    with pytest.raises(ValueError, match="drop_unread must be 0 or 1"):
        open_transport("pty://?drop_unread=yes")
    with open_transport("pty://?drop_unread=0") as t:
        assert t.drop_unread is False
