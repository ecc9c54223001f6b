import errno

import pytest
import serial

import mobigrasp.protocol as p
from mobigrasp.link import (
    FdTransport,
    Link,
    LinkClosed,
    inproc_pair,
    list_backends,
    open_transport,
    registry,
)
from mobigrasp.link import serial_transport as st_mod


def test_unknown_scheme_is_named():
    with pytest.raises(ValueError, match=r"unknown transport scheme 'bogus' in 'bogus://x'"):
        open_transport("bogus://x")
    with pytest.raises(ValueError, match="pty URL takes no path"):
        open_transport("pty:///dev/pts/1")
    with pytest.raises(ValueError, match="inproc URL needs a name"):
        open_transport("inproc://")
    with pytest.raises(ValueError, match="non-empty str"):
        open_transport("")


def test_list_backends():
    names = list_backends()
    assert {"pty", "inproc", "loop", "spy", "serial"} <= set(names)


def test_register_backend_is_used():
    made = []

    def factory(url):
        a, _b = inproc_pair("custom")
        made.append(url)
        return a

    registry.register_backend("mytest", factory)
    t = open_transport("mytest://thing")
    assert made == ["mytest://thing"] and t.read() == b""
    with pytest.raises(ValueError, match="identifier"):
        registry.register_backend("no good", factory)


def test_pyserial_url_schemes_open(tmp_path):
    log = tmp_path / "spy.txt"
    with open_transport("pty://") as master, open_transport(
        f"spy://{master.slave_path}?file={log}"
    ) as spy:
        master.write(b"abc")
        assert spy.wait_readable(30.0) and spy.read() == b"abc"
    assert "abc" in log.read_text()


def test_missing_device_raises_clear_error():
    with pytest.raises(serial.SerialException, match="could not open port"):
        open_transport("/dev/does-not-exist-mobigrasp")


def test_pty_ioctl_refusal_falls_back_to_raw_descriptor(monkeypatch):
    master = open_transport("pty://")

    def refuse(url, baudrate=115200):
        raise serial.SerialException(errno.EINVAL, "Invalid argument (DTR ioctl on a pty)")

    monkeypatch.setattr(st_mod, "SerialTransport", refuse)
    slave = open_transport(master.slave_path)
    try:
        assert isinstance(slave, FdTransport)
        master.write(b"ping\x00\r\n\x03")
        got = b""
        while len(got) < 8:
            assert slave.wait_readable(30.0)
            got += slave.read()
        assert got == b"ping\x00\r\n\x03"
        slave.write(b"pong")
        assert master.wait_readable(30.0) and master.read() == b"pong"
        slave.close()
        with pytest.raises(LinkClosed):
            while master.wait_readable(30.0):
                master.read()
    finally:
        master.close()


def test_other_open_errors_are_not_swallowed(monkeypatch):
    master = open_transport("pty://")

    def refuse(url, baudrate=115200):
        raise serial.SerialException(errno.EACCES, "Permission denied")

    monkeypatch.setattr(st_mod, "SerialTransport", refuse)
    try:
        with pytest.raises(serial.SerialException, match="Permission denied"):
            open_transport(master.slave_path)
    finally:
        master.close()


def test_link_counts_undecodable_frames_and_reports_them():
    a, b = inproc_pair()
    bad = []
    rx = Link(b, known_types=None, on_bad_frame=lambda f, e: bad.append((f.msg_type, e)))
    tx = Link(a)
    a.write(p.encode_frame(p.Frame(1, 5, 0x13, b"\x01")))  # STOP with a 1-byte payload
    a.write(p.encode_frame(p.Frame(1, 6, 0x77, b"")))  # unknown type
    a.write(b"\x12\x34\x00")  # line noise
    wire = tx.send_with_seq(p.Gripper(250), 200)
    assert wire == p.encode_message(p.Gripper(250), 200) == tx.last_wire
    got = rx.poll()
    assert [(r.seq, r.msg) for r in got] == [(200, p.Gripper(250))]
    assert rx.stats["decode_errors"] == 2
    assert [t for t, _ in bad] == [0x13, 0x77]
    assert bad[0][1].nack_reason == p.NACK_BAD_LENGTH
    assert bad[1][1].nack_reason == p.NACK_UNKNOWN_TYPE
    assert rx.stats["parser_truncated"] + rx.stats["parser_crc_errors"] \
        + rx.stats["parser_cobs_errors"] == 1
    strict = Link(inproc_pair()[1])
    assert strict.parser.known_types == frozenset(p.MESSAGE_TYPES)


def test_link_send_rejects_invalid_messages_before_writing():
    a, b = inproc_pair()
    tx = Link(a)
    msg = p.SetWheels(0, 0)
    object.__setattr__(msg, "left_mmps", 5000)
    with pytest.raises(ValueError, match="SetWheels.left_mmps"):
        tx.send(msg)
    assert b.read() == b"" and tx.stats["tx_frames"] == 0


def test_link_poll_returns_last_messages_before_raising_link_closed():
    a, b = inproc_pair()
    rx = Link(b)
    Link(a).send(p.Heartbeat(1))
    a.close()
    got = rx.poll()  # the data, then the closed peer inside the same poll
    assert [r.msg for r in got] == [p.Heartbeat(1)]
    with pytest.raises(LinkClosed):
        rx.poll()
