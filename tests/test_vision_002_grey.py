import numpy as np
import pytest

from host.vision.grey import to_grey


def test_grey_matches_float_weights_within_one():
    rng = np.random.default_rng(1)
    rgb = rng.integers(0, 256, size=(24, 32, 3), dtype=np.uint8)
    grey, ops = to_grey(rgb)
    assert grey.shape == (24, 32) and grey.dtype == np.uint8
    ref = rgb[..., 0] * 0.299 + rgb[..., 1] * 0.587 + rgb[..., 2] * 0.114
    assert np.max(np.abs(grey.astype(float) - ref)) <= 1.5
    assert ops.pixels_read == 3 * 24 * 32
    assert ops.pixels_written == 24 * 32
    assert ops.cycles() > 0


def test_grey_extremes_and_exact_formula():
    rgb = np.array([[[255, 255, 255], [0, 0, 0], [255, 0, 0], [10, 200, 30]]], dtype=np.uint8)
    grey, _ = to_grey(rgb)
    assert grey.tolist() == [[255, 0, (77 * 255) >> 8, (77 * 10 + 150 * 200 + 29 * 30) >> 8]]


@pytest.mark.parametrize("bad", [
    np.zeros((4, 4), np.uint8), np.zeros((4, 4, 4), np.uint8), np.zeros((4, 4, 3), np.float32),
    np.zeros((0, 4, 3), np.uint8), [[1, 2, 3]],
])
def test_grey_rejects_bad_input(bad):
    with pytest.raises(ValueError):
        to_grey(bad)


@pytest.mark.parametrize("sigma", [0, 5, 12, 30])
def test_noise_sigma_estimate(sigma):
    from host.vision.grey import noise_sigma
    rng = np.random.default_rng(sigma)
    y, x = np.mgrid[0:240, 0:320]
    smooth = 120 + 40 * np.sin(x / 40.0) * np.cos(y / 30.0)  # floor-like shading
    grey = np.clip(np.rint(smooth + rng.normal(0, sigma, smooth.shape)), 0, 255).astype(np.uint8)
    est, ops = noise_sigma(grey)
    assert abs(est - sigma) <= max(1.0, 0.15 * sigma)
    assert ops.pixels_read > 0
    with pytest.raises(ValueError):
        noise_sigma(np.zeros((4, 4, 3), np.uint8))
