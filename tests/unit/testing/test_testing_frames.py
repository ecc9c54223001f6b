"""mobigrasp.testing.frames reads the camera server of `sim`: /frame.png exactly, the stream in
order."""

import numpy as np
import pytest

from mobigrasp.cosim.serve.mjpeg import CameraServer
from mobigrasp.testing.frames import MjpegReader, frame_url, read_frame


@pytest.fixture
def camera():
    server = CameraServer(0)
    yield server
    server.close()


def test_frame_png_is_the_published_frame_in_bgr(camera):
    rgb = np.random.default_rng(3).integers(0, 256, (24, 32, 3), dtype=np.uint8)
    camera.publish(rgb)
    assert frame_url(camera.url).endswith("/frame.png")
    assert np.array_equal(read_frame(camera.url), rgb[:, :, ::-1])


def test_the_stream_gives_each_new_frame(camera):
    camera.publish(np.full((24, 32, 3), 30, np.uint8))
    reader = MjpegReader(camera.url)
    try:
        first = reader.read()
        camera.publish(np.full((24, 32, 3), 200, np.uint8))
        second = reader.read()
    finally:
        reader.close()
    assert abs(float(first.mean()) - 30) < 3 and abs(float(second.mean()) - 200) < 3
