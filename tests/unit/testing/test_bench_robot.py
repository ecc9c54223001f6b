"""pytest --robot-port/--robot-camera: the robot fixture on a device (here the emulated MCU on a
pty standing in for the robot) and a camera (an image sequence written by the test)."""

import subprocess
import sys

import cv2
import numpy as np
import pytest

from mobigrasp.protocol import HelloAck

pytestmark = pytest.mark.timeout(240)

BENCH_TESTS = '''
import cv2
import numpy as np
import serial

from mobigrasp.protocol import PROTOCOL_VERSION, Hello, encode_message


def test_port_and_camera(emulated_robot):
    robot = emulated_robot("paper000-exp1", clock="test")
    assert robot.port == {port!r}
    with serial.Serial(robot.port, 115200, timeout=0) as ser:
        ser.write(encode_message(Hello(PROTOCOL_VERSION, "bench-host", 0), 1))
    for i in range(3):
        assert np.array_equal(robot.frame(), cv2.imread({shots!r} % i))


def test_truth(emulated_robot):
    emulated_robot("paper000-exp1").truth()


def test_clock(emulated_robot):
    emulated_robot("paper000-exp1", clock="test").advance_ms(10)
'''


def test_robot_port_and_camera_make_the_fixture_a_bench_robot(emulated_mcu, tmp_path):
    shots = str(tmp_path / "shot_%03d.png")
    rng = np.random.default_rng(7)
    for i in range(3):  # lossless and different: a frame read is the one written
        cv2.imwrite(shots % i, rng.integers(0, 256, (48, 64, 3), dtype=np.uint8))
    test_file = tmp_path / "test_on_the_bench.py"
    test_file.write_text(BENCH_TESTS.format(port=emulated_mcu.port, shots=shots))
    out = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-rs", "-p", "no:cacheprovider", str(test_file),
         "--robot-port", emulated_mcu.port, "--robot-camera", shots],
        cwd=tmp_path, capture_output=True, text=True, timeout=200)
    assert "1 passed, 2 skipped" in out.stdout, out.stdout + out.stderr
    assert "truth() (the world's ground truth) needs the emulated robot" in out.stdout
    assert "advance_ms() (a clock the test moves) needs the emulated robot" in out.stdout
    # the HELLO the test wrote reached the device: the MCU answers it
    emulated_mcu.wait_from_host()
    emulated_mcu.advance_ms(10)
    assert any(isinstance(m, HelloAck) for _, m in emulated_mcu.sent())


def test_a_camera_that_does_not_open_is_named(tmp_path):
    from mobigrasp.testing.bench_robot import BenchRobot, camera_source

    assert camera_source("0") == 0 and camera_source("a.avi") == "a.avi"
    robot = BenchRobot("paper000-exp1", "/dev/null", str(tmp_path / "missing.avi"))
    with pytest.raises(RuntimeError, match="missing.avi.*cannot open"):
        robot.frame()
