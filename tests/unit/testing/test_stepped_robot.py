"""emulated_robot(clock="test"): a host loop and the robot advance in one deterministic test."""

import hashlib
import math
import re
import subprocess
import sys
from pathlib import Path

import pytest
import serial

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
from mobigrasp.testing.expect import ExpectationFailed

pytestmark = pytest.mark.timeout(240)
SCENARIO = "paper000-exp1"
ROOT = Path(__file__).resolve().parents[3]


class LoopHost:
    """A host program's loop: HELLO, then every 20 ms a heartbeat and the wheels' speeds."""

    def __init__(self, port):
        self.ser = serial.Serial(port, 115200, timeout=0)
        self.parser = FrameParser()
        self.seq = 0
        self.received = []

    def send(self, msg):
        self.seq = (self.seq + 1) % 256
        self.ser.write(encode_message(msg, self.seq))

    def read(self):
        for frame in self.parser.feed(self.ser.read(65536)):
            self.received.append(decode_frame(frame))


def drive(robot):
    """HELLO, 1 s of heartbeats and SetWheels(120, 120), a frame every 100 ms; what the host
    received and the frames' digests."""
    host = LoopHost(robot.port)
    host.send(Hello(PROTOCOL_VERSION, "loop-host", 0))
    robot.expect(lambda r: host.read() or any(isinstance(m, HelloAck) for m in host.received),
                 within_ms=100)
    frames = []
    for tick in range(50):
        host.send(Heartbeat(robot.now_us))
        host.send(SetWheels(120, 120))
        robot.advance_ms(20)
        host.read()
        if tick % 5 == 4:
            frames.append(hashlib.sha256(robot.frame().tobytes()).hexdigest())
    host.ser.close()
    return host.received, frames


def test_a_host_loop_gives_the_same_telemetry_and_frames_twice(emulated_robot):
    first, second = emulated_robot(SCENARIO, clock="test"), emulated_robot(SCENARIO, clock="test")
    start = first.truth()
    received_1, frames_1 = drive(first)
    received_2, frames_2 = drive(second)

    telemetry = [m for m in received_1 if isinstance(m, Telemetry)]
    assert len(telemetry) >= 10
    assert telemetry[-1].enc_left > telemetry[0].enc_left  # the wheels turned
    assert telemetry == first.telemetry()[:len(telemetry)]  # the host read what the MCU sent
    moved = first.truth()
    assert math.dist(moved.base[:2], start.base[:2]) > 0.03  # the base drove
    assert len(set(frames_1)) > 1  # the view changed as the base drove
    assert received_1 == received_2
    assert frames_1 == frames_2
    assert first.truth() == second.truth()
    assert first.nacks() == []


def test_expect_fails_with_what_was_last_seen(emulated_robot):
    robot = emulated_robot(SCENARIO, clock="test")
    with pytest.raises(ExpectationFailed, match=r"within 30 ms.*t=0\.030 s.*truth: Truth"):
        robot.expect(lambda r: r.truth().held, within_ms=30, step_ms=10)
    assert robot.now_us == 30_000


def test_close_writes_the_run_folder(emulated_robot):
    robot = emulated_robot(SCENARIO, clock="test", time_limit_s=0.05)
    robot.advance_ms(40)
    with pytest.raises(RuntimeError, match="time_limit"):
        robot.advance_ms(20)
    summary = robot.close()
    assert summary["sim_time_s"] == pytest.approx(0.05)
    assert summary["status"] == "finished" and summary["line"]["dropped_to_host_bytes"] == 0
    assert (robot.run_dir / "trace.jsonl").exists()


def test_readme_test_clock_example_runs_as_is(tmp_path):
    """The README's test-clock example, copied into a file and run by pytest as a user would."""
    text = (ROOT / "README.md").read_text()
    section = text.split("### Testing your own host program against the emulated robot", 1)[1]
    code = re.findall(r"```python\n(.*?)```", section, re.S)[1]
    assert 'clock="test"' in code and "robot.expect(" in code
    (tmp_path / "test_readme_test_clock.py").write_text(code)
    res = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                          "test_readme_test_clock.py"], cwd=tmp_path, capture_output=True,
                         text=True, timeout=200)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "1 passed" in res.stdout
