"""The real board's host driver (drivers/realtime.py): the OpenCV camera behind Camera.poll,
and the loop's ends, with a manual clock and fake app and port (no wall clock is read)."""

import cv2
import numpy as np
import pytest

from mobigrasp.drivers import realtime
from mobigrasp.host.hal import Camera, CameraFrame, ManualClock
from mobigrasp.link.base import LinkClosed


def _video(path, n=3):
    out = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 15, (320, 240))
    for k in range(n):
        img = np.zeros((240, 320, 3), np.uint8)
        img[:, :, 2] = 60 * (k + 1)  # red in BGR
        out.write(img)
    out.release()
    return path


def test_a_video_file_is_polled_at_the_camera_rate(tmp_path):
    clock = ManualClock()
    cam = realtime.OpenCvCamera(str(_video(tmp_path / "v.avi")), clock)
    try:
        assert isinstance(cam, Camera)
        first = cam.poll()
        assert isinstance(first, CameraFrame) and first.seq == 0 and first.capture_us == 0
        assert first.rgb.shape == (240, 320, 3) and first.rgb[..., 0].mean() > 40  # RGB order
        assert cam.poll() is None  # the next one is 1/15 s later
        clock.set_us(66_667)
        second = cam.poll()
        assert second.seq == 1 and second.capture_us == 66_667
        assert second.rgb[..., 0].mean() > first.rgb[..., 0].mean()
    finally:
        cam.close()


def test_a_source_that_does_not_open_is_refused(tmp_path):
    with pytest.raises(ValueError, match="cannot open camera source"):
        realtime.OpenCvCamera(str(tmp_path / "missing.avi"), ManualClock())


class _App:
    def __init__(self, steps_to_finish):
        self.left = steps_to_finish
        self.now_us = 0
        self.uart, self.frames = [], []

    @property
    def finished(self):
        return self.left <= 0

    def on_uart(self, data, t_us):
        self.uart.append((t_us, data))

    def on_frame(self, seq, capture_us, arrival_us, rgb):
        self.frames.append((seq, capture_us, arrival_us))

    def advance_to(self, t_us):
        self.now_us = t_us
        self.left -= 1

    def resolve_vision(self):
        pass

    def take_output(self, t_us):
        return [(t_us, b"\x01\x02")]


class _Port:
    def __init__(self, clock, chunks, close_after=None):
        self.clock, self.chunks, self.close_after = clock, list(chunks), close_after
        self.written = []

    def read(self):
        if self.close_after is not None and len(self.written) >= self.close_after:
            raise LinkClosed("gone")
        return self.chunks.pop(0) if self.chunks else b""

    def write(self, data):
        self.written.append(data)

    def wait_readable(self, timeout_s):
        self.clock.advance_us(2_000)  # the loop's wait, on the manual clock
        return bool(self.chunks)

    def close(self):
        pass


class _Cam(Camera):
    def __init__(self):
        self.n = 0

    def poll(self):
        self.n += 1
        return CameraFrame(self.n, 0, None) if self.n == 2 else None

    def close(self):
        pass


def test_the_loop_runs_the_app_until_its_task_ends():
    clock = ManualClock()
    app, port = _App(steps_to_finish=4), _Port(clock, [b"ab", b"cd"])
    assert realtime.run(app, port, clock, _Cam()) == "finished"
    assert [d for _, d in app.uart] == [b"ab", b"cd"]
    assert app.frames == [(2, 0, 1)]  # arrival no earlier than the program's own time
    assert port.written == [b"\x01\x02"] * 4


def test_the_loop_stops_when_the_port_vanishes():
    clock = ManualClock()
    app = _App(steps_to_finish=100)
    assert realtime.run(app, _Port(clock, [], close_after=3), clock) == "port_closed"
    assert not app.finished
