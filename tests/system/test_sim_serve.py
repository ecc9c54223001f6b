"""``mobigrasp sim``: the robot served to a host program that is not mobigrasp's."""

import json
import os
import re
import socket
import subprocess
import sys
import urllib.error
import urllib.request
from pathlib import Path

import cv2
import numpy as np
import pytest

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.serve.external_host import ExternalHost
from mobigrasp.cosim.serve.mjpeg import CameraServer
from mobigrasp.link.registry import open_transport
from mobigrasp.protocol import PROTOCOL_VERSION, Hello, Telemetry, encode_message

ROOT = Path(__file__).resolve().parents[2]
SAFETY_S = 120  # limits only: nothing asserts on them


def sim(*args, cwd):
    return subprocess.run([sys.executable, "-m", "mobigrasp", "sim", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=SAFETY_S)


def test_bad_scenario_is_exit_2_with_one_line(tmp_path):
    res = sim("no-such-scenario", "--camera-port", "0", cwd=tmp_path)
    assert res.returncode == 2 and res.stdout == ""
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "no-such-scenario" in lines[0]
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"\xff\xfe[meta\n")
    res = sim(str(bad), "--camera-port", "0", cwd=tmp_path)
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1
    assert "bad.toml" in res.stderr and "Traceback" not in res.stderr


def test_bad_options_are_exit_2_without_traceback(tmp_path):
    for args in (("--seed", "-5"), ("--speed", "nan"), ("--speed", "0"), ("--mcu", "nope"),
                 ("--time-limit-s", "inf")):
        res = sim("paper000-exp1", "--camera-port", "0", *args, cwd=tmp_path)
        assert res.returncode == 2, args
        assert args[0] in res.stderr and "Traceback" not in res.stderr, args


def test_out_that_is_a_file_is_exit_2(tmp_path):
    (tmp_path / "f").write_text("mine")
    res = sim("paper000-exp1", "--camera-port", "0", "--out", str(tmp_path / "f"), cwd=tmp_path)
    assert res.returncode == 2 and "is a file" in res.stderr
    assert (tmp_path / "f").read_text() == "mine"


def test_camera_port_in_use_is_exit_2_naming_it(tmp_path):
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        res = sim("paper000-exp1", "--camera-port", str(port), cwd=tmp_path)
    assert res.returncode == 2 and res.stdout == ""
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and f"camera port {port}" in lines[0]
    res = sim("paper000-exp1", "--camera-port", "70000", cwd=tmp_path)
    assert res.returncode == 2 and "--camera-port" in res.stderr


def test_camera_server_serves_png_and_mjpeg_on_localhost_only():
    server = CameraServer(0)
    try:
        assert server.host == "127.0.0.1"
        rng = np.random.default_rng(1)
        frame = rng.integers(0, 255, (240, 320, 3), dtype=np.uint8)
        server.publish(frame)
        with urllib.request.urlopen(server.png_url, timeout=10) as r:
            assert r.headers["Content-Type"] == "image/png"
            png = cv2.imdecode(np.frombuffer(r.read(), np.uint8), cv2.IMREAD_COLOR)
        assert np.array_equal(png[:, :, ::-1], frame)  # lossless, RGB published, BGR decoded
        with pytest.raises(urllib.error.HTTPError) as err:
            urllib.request.urlopen(server.url.replace("stream.mjpg", "nope"), timeout=10)
        assert err.value.code == 404
        with urllib.request.urlopen(server.url, timeout=10) as r:
            ctype = r.headers["Content-Type"]
            assert ctype.startswith("multipart/x-mixed-replace; boundary=")
            boundary = ctype.split("boundary=")[1]
            assert r.readline().strip() == f"--{boundary}".encode()
            headers = {}
            while (line := r.readline().strip()):
                k, v = line.decode().split(": ", 1)
                headers[k] = v
            assert headers["Content-Type"] == "image/jpeg"
            jpg = cv2.imdecode(np.frombuffer(r.read(int(headers["Content-Length"])), np.uint8),
                               cv2.IMREAD_COLOR)
        assert jpg.shape == (240, 320, 3)
    finally:
        server.close()
    assert server.parts_sent >= 1


def test_external_host_reports_what_the_program_wrote_and_decodes_both_ways():
    transport = open_transport("pty://")
    host = ExternalHost(transport)
    fd = os.open(transport.slave_path, os.O_RDWR | os.O_NOCTTY)
    try:
        hello = encode_message(Hello(PROTOCOL_VERSION, "prog", 0), 3)
        os.write(fd, hello)
        tel = encode_message(Telemetry(7, 1, 2, (1500,) * 6, (0xFFFF,) * 5, 4, 0, 0, 0, 0), 9)
        host.port.write(tel)  # the MCU's bytes go to the program at once
        assert os.read(fd, 4096) == tel
        done = host.exchange(ls.Grant(start_us=5000, until_us=10000, uart=((4800, len(tel)),)))
        assert done.writes == ((5000, len(hello)),)
        assert host.port.read() == hello and host.port.read() == b""
        wires = {e["dir"]: e for e in done.events}
        assert wires["to_mcu"]["msg"] == "Hello" and wires["to_mcu"]["t_us"] == 5000
        assert wires["to_mcu"]["fields"]["host_id"] == "prog"
        assert wires["to_host"]["msg"] == "Telemetry" and wires["to_host"]["t_us"] == 4800
        assert wires["to_host"]["fields"]["servo_us"] == [1500] * 6
        # nothing new written: nothing announced
        assert host.exchange(ls.Grant(start_us=10000, until_us=15000)).writes == ()
    finally:
        os.close(fd)
    host.exchange(ls.Grant(start_us=15000, until_us=20000))
    assert host.host_closed  # the program closed its end
    host.close()


def readme_example() -> str:
    text = (ROOT / "README.md").read_text()
    section = text.split("### Testing your own host program against the emulated robot", 1)[1]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_readme_example_runs_as_is(tmp_path):
    """The README's complete example (a minimal external host: pyserial, cv2.VideoCapture and
    the protocol package: HELLO, frames, the waist commanded, its pulse seen in telemetry)
    through the emulated_robot fixture, copied into a file and run by pytest as a user would."""
    code = readme_example()
    assert "emulated_robot" in code and "cv2.VideoCapture" in code and "serial.Serial" in code
    (tmp_path / "test_readme_example.py").write_text(code)
    res = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                          "test_readme_example.py"], cwd=tmp_path, capture_output=True,
                         text=True, timeout=3 * SAFETY_S)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "1 passed" in res.stdout


def test_the_fixture_yields_the_summary_of_a_session_the_host_left_running(emulated_robot):
    """A host that never closes the port: the session is stopped (as SIGTERM stops `sim`) and
    still writes its run folder, with the world's judgement in it."""
    robot = emulated_robot("paper000-exp1", speed=2.0, plots=False)
    assert robot.port.startswith("/dev/pts/") and robot.camera_url.endswith("/stream.mjpg")
    # sim's session serves it from this process (services/sim_job.py): no `mobigrasp sim` child
    children = [c for task in Path("/proc/self/task").iterdir()
                for c in (task / "children").read_text().split()]
    assert children == []
    png_url = robot.camera_url.replace("stream.mjpg", "frame.png")
    for attempt in range(10):  # each waits up to 5 s on the server for the first frame
        try:
            with urllib.request.urlopen(png_url, timeout=SAFETY_S) as r:
                png = cv2.imdecode(np.frombuffer(r.read(), np.uint8), cv2.IMREAD_COLOR)
            break
        except urllib.error.HTTPError as exc:
            assert exc.code == 503 and attempt < 9  # "no frame yet" on a slow start only
    assert png.shape == (240, 320, 3)
    robot.stop()
    s = robot.summary
    assert s["end_reason"] == "terminated" and s["grasped"] is False
    assert s["contacts"] == 0 and "unsafe_actuations" in s["safety"]
    assert (robot.run_dir / "trace.jsonl").exists()
    assert robot.exit_code == 1  # nothing grasped


@pytest.mark.slow
def test_sim_and_mobigrasp_host_as_two_processes_grasp(tmp_path):
    """`mobigrasp sim --speed 1` and `mobigrasp host --port --camera`: the object is grasped
    within 40 s (simulated, paced to wall time) and the run folder says so."""
    out = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-m", "mobigrasp", "sim", "paper000-exp1",
                             "--speed", "1", "--camera-port", "0", "--out", str(out),
                             "--quiet"], cwd=tmp_path, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        serial = proc.stdout.readline().split(": ", 1)[1].strip()
        camera = proc.stdout.readline().split(": ", 1)[1].strip()
        host = subprocess.run([sys.executable, "-m", "mobigrasp", "host", "--port", serial,
                               "--camera", camera, "--method", "000"], cwd=tmp_path,
                              capture_output=True, text=True, timeout=3 * SAFETY_S)
        rest, err = proc.communicate(timeout=SAFETY_S)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert host.returncode == 0, host.stderr  # DONE
    assert "state DONE" in host.stderr
    assert proc.returncode == 0, err
    assert "GRASPED (host_closed)" in rest
    summary = json.loads((out / "summary.json").read_text())
    assert summary["grasped"] and summary["end_reason"] == "host_closed"
    assert summary["time_to_grasp_s"] < 40.0
    assert summary["contacts"] == 0 and summary["safety"]["unsafe_actuations"] == 0
    assert (out / "report.html").exists()
    wires = [json.loads(line) for line in (out / "trace.jsonl").read_text().splitlines()
             if '"wire"' in line]
    assert any(w["dir"] == "to_mcu" and w.get("msg") == "Hello" for w in wires)
    assert any(w["dir"] == "to_mcu" and w.get("msg") == "Gripper" or
               (w.get("msg") == "SetServos" and w["fields"]["targets"][0] == 1000)
               for w in wires)


@pytest.mark.slow
def test_stream_rate_and_serial_byte_rate_at_speed_1(tmp_path):
    """At --speed 1 the MJPEG stream delivers the camera's 15 fps (± 1) and the serial line the
    MCU's modelled byte rate (bytes per wall second within 10 % of bytes per simulated second
    by the telemetry's own clock). Wall time is measured, never slept."""
    import time

    import serial as pyserial

    from mobigrasp.protocol import FrameParser, decode_frame

    proc = subprocess.Popen([sys.executable, "-m", "mobigrasp", "sim", "paper000-exp1",
                             "--speed", "1", "--camera-port", "0", "--out",
                             str(tmp_path / "run"), "--quiet", "--no-plots",
                             "--no-wait-host"], cwd=tmp_path,  # the clock runs with no host
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        port = proc.stdout.readline().split(": ", 1)[1].strip()
        url = proc.stdout.readline().split(": ", 1)[1].strip()
        cap = cv2.VideoCapture(url)
        stamps = []
        for _ in range(61):  # 4 s of frames
            ok, _ = cap.read()
            assert ok
            stamps.append(time.monotonic())
        cap.release()
        ser = pyserial.Serial(port, 115200, timeout=0.05)
        parser, got, t_wall, t_sim = FrameParser(), 0, [], []
        while len(t_sim) < 150:  # 3 s of 50 Hz telemetry
            data = ser.read(4096)
            frames = parser.feed(data)
            if t_sim:
                got += len(data)
            for f in frames:
                m = decode_frame(f)
                if isinstance(m, Telemetry):
                    t_sim.append(m.time_us)
                    t_wall.append(time.monotonic())
        ser.close()
        proc.communicate(timeout=SAFETY_S)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    fps = (len(stamps) - 1) / (stamps[-1] - stamps[0])
    assert 14.0 <= fps <= 16.0, fps
    per_sim_s = got / ((t_sim[-1] - t_sim[0]) / 1e6)
    per_wall_s = got / (t_wall[-1] - t_wall[0])
    assert per_sim_s > 2000  # 50 Hz telemetry of 51 bytes
    assert abs(per_wall_s / per_sim_s - 1.0) < 0.10, (per_wall_s, per_sim_s)


def test_ctrl_c_ends_the_session_and_writes_the_run_folder(tmp_path):
    import signal

    out = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-m", "mobigrasp", "sim", "paper000-exp1",
                             "--camera-port", "0", "--out", str(out), "--quiet", "--no-plots"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    try:
        assert proc.stdout.readline().startswith("serial: /dev/pts/")
        assert proc.stdout.readline().startswith("camera: http://127.0.0.1:")
        proc.send_signal(signal.SIGINT)
        rest, err = proc.communicate(timeout=SAFETY_S)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 1 and "Traceback" not in err
    assert "not grasped (interrupted)" in rest
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "finished" and summary["end_reason"] == "interrupted"


def test_run_and_sim_write_one_summary_schema(tmp_path):
    """`mobigrasp run` and `mobigrasp sim` are one wiring (cosim/sim_side.py): the same keys,
    the MCU's counters under "mcu" and its backend under "mcu_backend"; the served session adds
    only what an external host is given (pty, camera, pacing) and the line's and camera's
    counters."""
    from mobigrasp.cosim.serve.session import SimOptions, serve
    from mobigrasp.services.run_job import RunOptions, execute, resolve_scenario

    run, _ = execute(RunOptions(scenario="paper000-exp1", transport="inproc",
                                out=tmp_path / "run", progress=False, plots=False,
                                time_limit_s=0.3))
    sim = serve(SimOptions(scenario="paper000-exp1", speed=100.0, out=tmp_path / "sim",
                           time_limit_s=0.3, resolved=resolve_scenario("paper000-exp1")),
                lambda serial, camera, serial_tcp: None)
    assert set(run) <= set(sim)
    assert set(sim) - set(run) == {"serial", "camera", "speed", "wait_host", "line",
                                   "camera_frames", "run_folder"}
    for summary in (run, sim):
        assert summary["mcu_backend"] == "python" and summary["status"] == "finished"
        assert summary["mcu"]["telemetry_sent"] > 0
    assert sim["method"] == "external" and sim["task_state"] == "external"
    assert sim["end_reason"] == "time_limit" and sim["time_limit_s"] == 0.3
    on_disk = json.loads((tmp_path / "sim" / "summary.json").read_text())
    assert on_disk["line"] == sim["line"] and on_disk["mcu"] == sim["mcu"]
