"""``sim`` for CI: --wait-host, --tcp-port, --fault, the host's traffic in summary, report and
trace.mcap."""

import json
import socket
import subprocess
import sys

import pytest
from mcap.reader import make_reader

from mobigrasp.cosim.serve.tcp_bridge import TcpPortInUse, TcpSerialBridge
from mobigrasp.link.registry import open_transport
from mobigrasp.protocol import (
    PROTOCOL_VERSION,
    FrameParser,
    Heartbeat,
    Hello,
    HelloAck,
    SetWheels,
    Telemetry,
    decode_frame,
    encode_message,
)
from mobigrasp.services.mcap_out import wire_messages
from mobigrasp.services.wire_traffic import host_traffic, traffic_lines

SAFETY_S = 120  # limits only: nothing asserts on them


def wire(direction, t_us, seq, msg, **fields):
    return {"ev": "wire", "dir": direction, "t_us": t_us, "seq": seq, "msg": msg,
            "fields": fields}


def tele(t_us, trips):
    return wire("to_host", t_us, 0, "Telemetry", watchdog_trips=trips)


def test_host_traffic_counts_rates_nacks_latency_trips_and_wheels():
    events = [
        {"ev": "truth", "t_us": 0, "x_m": 0.0, "y_m": 0.0, "heading_rad": 0.0},
        tele(10_000, 1),  # a trip before the host came
        wire("to_mcu", 100_000, 1, "Hello", proto_version=1),
        wire("to_host", 102_000, 0, "Ack", acked_seq=1),
        wire("to_mcu", 100_000, 2, "SetWheels", left_mmps=100, right_mmps=100),
        {"ev": "truth", "t_us": 100_000, "x_m": 0.0, "y_m": 0.0, "heading_rad": 0.0},
        wire("to_host", 106_000, 0, "Nack", acked_seq=2, reason=4),
        tele(150_000, 1),
        {"ev": "truth", "t_us": 200_000, "x_m": 0.009, "y_m": 0.0, "heading_rad": 0.0},
        wire("to_mcu", 300_000, 3, "Heartbeat", time_us=0),
        tele(400_000, 2),
        {"ev": "end", "t_us": 500_000},
    ]
    t = host_traffic(events)
    assert t["host_first_frame_s"] == 0.1 and t["frames_to_mcu"] == 3
    assert t["command_rate_hz"] == 7.5  # 3 frames in 0.4 s from the first
    assert t["commands_by_type"] == {"Heartbeat": 1, "Hello": 1, "SetWheels": 1}
    assert t["nacks_by_reason"] == {"NOT_READY": 1}
    assert t["ack_latency_ms"] == {"count": 1, "median": 2.0, "max": 2.0}
    assert t["watchdog_trips_before_host"] == 1 and t["watchdog_trips"] == 2
    assert t["watchdog_trip_s"] == [0.4]
    assert t["wheels"]["commanded_mean_mmps"] == [100.0, 100.0]
    assert t["wheels"]["measured_mean_mmps"] == [90.0, 90.0]
    assert t["wheels"]["mean_abs_error_mmps"] == 10.0
    assert "NOT_READY 1" in " ".join(traffic_lines(t))


def test_wire_events_become_topics():
    state = {}
    assert [topic for topic, _ in wire_messages(
        wire("to_mcu", 5, 2, "SetWheels", left_mmps=1, right_mmps=2), state)] == [
        "/wire/to_mcu", "/wheels/commanded"]
    nack = wire_messages(wire("to_host", 6, 0, "Nack", acked_seq=2, reason=4), state)
    assert nack[1] == ("/wire/nacks", {"timestamp": {"sec": 0, "nsec": 6000}, "acked_seq": 2,
                                       "reason": "NOT_READY", "count": 1})
    assert len(wire_messages(tele(7, 0), state)) == 1
    assert wire_messages(tele(8, 1), state)[1][0] == "/wire/watchdog"
    assert len(wire_messages(tele(9, 1), state)) == 1  # no new trip


def test_tcp_bridge_relays_both_ways_and_closes_the_slave_with_the_client():
    transport = open_transport("pty://")
    bridge = TcpSerialBridge(transport.slave_path, 0)
    try:
        with pytest.raises(TcpPortInUse, match=f"--tcp-port {bridge.port}"):
            TcpSerialBridge(transport.slave_path, bridge.port)
        with socket.create_connection(("127.0.0.1", bridge.port), timeout=SAFETY_S) as c:
            c.sendall(b"ping")
            got = b""
            while len(got) < 4 and transport.wait_readable(SAFETY_S):
                got += transport.read()
            assert got == b"ping"
            transport.write(b"pong")
            assert c.recv(16) == b"pong"
        # the client went: the bridge closed the slave, the session sees its host close
        from mobigrasp.link.base import LinkClosed

        with pytest.raises(LinkClosed):
            while transport.wait_readable(SAFETY_S):
                transport.read()
    finally:
        bridge.close()
        transport.close()
    assert bridge.stats() == {"clients": 1, "bytes_to_pty": 4, "bytes_to_client": 4}


def test_bad_fault_and_tcp_port_are_exit_2(tmp_path):
    for args, word in ((("--fault", "no_such_key=1"), "no_such_key"),
                       (("--tcp-port", "70000"), "--tcp-port")):
        res = subprocess.run([sys.executable, "-m", "mobigrasp", "sim", "paper000-exp1", *args],
                             cwd=tmp_path, capture_output=True, text=True, timeout=SAFETY_S,
                             stdin=subprocess.DEVNULL)
        assert res.returncode == 2 and word in res.stderr and "Traceback" not in res.stderr


class TcpHost:
    """A minimal host over TCP: HELLO, then a heartbeat and SetWheels per telemetry."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=SAFETY_S)
        self.parser = FrameParser()
        self.seq = 0

    def send(self, msg):
        self.seq = (self.seq + 1) % 256
        self.sock.sendall(encode_message(msg, self.seq))

    def messages(self):
        data = self.sock.recv(4096)
        assert data, "the session closed the line"
        return [decode_frame(f) for f in self.parser.feed(data)]


@pytest.mark.slow
def test_sim_waits_for_a_host_that_comes_late_over_tcp(tmp_path):
    out = tmp_path / "run"
    proc = subprocess.Popen(
        [sys.executable, "-m", "mobigrasp", "sim", "paper000-exp1", "--wait-host",
         "--tcp-port", "0", "--out", str(out), "--quiet", "--time-limit-s", "30",
         "--fault", "uart_bit_error_rate=0"],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        stdin=subprocess.DEVNULL)
    try:
        lines = [proc.stdout.readline() for _ in range(3)]
        assert lines[0].startswith("serial: /dev/pts/") and lines[1].startswith("camera: ")
        assert lines[2].startswith("serial-tcp: tcp://127.0.0.1:")
        port = int(lines[2].rsplit(":", 1)[1])
        # the host comes late: the session waits for it (a watchdog would have tripped twice)
        with pytest.raises(subprocess.TimeoutExpired):
            proc.wait(timeout=1.5)
        host = TcpHost(port)
        host.send(Hello(PROTOCOL_VERSION, "tcp-host", 0))
        telemetry = 0
        acked = False
        while telemetry < 50:  # 1 s of telemetry at 50 Hz, answered as it comes
            for msg in host.messages():
                acked |= isinstance(msg, HelloAck)
                if isinstance(msg, Telemetry):
                    telemetry += 1
                    host.send(Heartbeat(msg.time_us))
                    host.send(SetWheels(100, 100))
        host.sock.close()
        rest, err = proc.communicate(timeout=SAFETY_S)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert acked
    assert "(host_closed)" in rest and "watchdog trips: 0 before the host's first frame" in rest
    summary = json.loads((out / "summary.json").read_text())
    traffic = summary["host_traffic"]
    assert summary["host_waited_s"] >= 1.5
    assert traffic["host_first_frame_s"] == 0.0  # the clock started at the host's HELLO
    assert traffic["watchdog_trips_before_host"] == 0 and traffic["watchdog_trips"] == 0
    assert summary["safety"]["watchdog_trips"] == 0
    assert traffic["commands_by_type"]["SetWheels"] >= 49
    assert traffic["ack_latency_ms"]["count"] >= 1  # the HELLO's ACK
    assert traffic["wheels"]["measured_mean_mmps"][0] > 20
    assert summary["line"]["tcp"]["clients"] == 1
    with open(out / "trace.mcap", "rb") as fh:
        wire_msgs = {}
        for _, channel, message in make_reader(fh).iter_messages(
                topics=["/wire/to_mcu", "/wire/to_host"]):
            wire_msgs.setdefault(channel.topic, []).append(json.loads(message.data)["msg"])
    assert wire_msgs["/wire/to_mcu"][0] == "Hello"
    assert wire_msgs["/wire/to_mcu"].count("SetWheels") == traffic["commands_by_type"][
        "SetWheels"]
    assert "HelloAck" in wire_msgs["/wire/to_host"] and "Telemetry" in wire_msgs["/wire/to_host"]
    assert "Host traffic" in (out / "report.html").read_text()


def test_wait_for_host_ends_at_the_first_valid_frame_and_delivers_all_at_t0():
    import os

    from mobigrasp.cosim import lockstep as ls
    from mobigrasp.cosim.serve.external_host import ExternalHost

    transport = open_transport("pty://")
    host = ExternalHost(transport)
    fd = os.open(transport.slave_path, os.O_RDWR | os.O_NOCTTY)
    try:
        os.write(fd, b"\x01\x02garbage\x00")  # not a frame: the wait goes on
        answers = iter([None, None, "terminated"])  # stop()'s answers, one per poll
        assert host.wait_for_host(lambda: next(answers), poll_s=0.01) == "terminated"
        hello = encode_message(Hello(PROTOCOL_VERSION, "late", 0), 1)
        os.write(fd, hello)
        assert host.wait_for_host(lambda: None, poll_s=5.0) is None
        done = host.exchange(ls.Grant(start_us=0, until_us=5000))
        assert done.writes == ((0, len(b"\x01\x02garbage\x00") + len(hello)),)
        assert [e["msg"] for e in done.events if "msg" in e] == ["Hello"]
    finally:
        os.close(fd)
        host.close()


def test_held_bytes_reach_the_pty_in_one_write_at_release():
    import os

    from mobigrasp.cosim import lockstep as ls
    from mobigrasp.cosim.serve.external_host import ExternalHost

    transport = open_transport("pty://")
    host = ExternalHost(transport, hold_to_host=True)
    fd = os.open(transport.slave_path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    try:
        tel = encode_message(Telemetry(7, 1, 2, (1500,) * 6, (0xFFFF,) * 5, 4, 0, 0, 0, 0), 9)
        host.port.write(tel[:10])
        host.port.write(tel[10:])
        with pytest.raises(BlockingIOError):
            os.read(fd, 4096)  # held: nothing on the pty yet
        done = host.exchange(ls.Grant(start_us=0, until_us=5000, uart=((4800, len(tel)),)))
        assert [e["msg"] for e in done.events] == ["Telemetry"]  # decoded all the same
        host.release_to_host()
        assert os.read(fd, 4096) == tel
        assert host.stats()["bytes_to_host"] == len(tel)
    finally:
        os.close(fd)
        host.close()
