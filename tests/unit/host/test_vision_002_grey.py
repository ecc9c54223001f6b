import numpy as np
import pytest

from mobigrasp.host.vision.grey import SHIFT, W_B, W_G, W_R, to_grey


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


def test_grey_is_the_integer_formula_for_every_colour():
    # to_grey rounds OpenCV's transform (fixed point): exact for all 2^24 colours, laid out
    # as one wide frame, as a column of narrow rows (SIMD tails) and as a strided view
    v = np.arange(256, dtype=np.uint8)
    rgb = np.empty((256, 256, 256, 3), np.uint8)
    rgb[..., 0], rgb[..., 1], rgb[..., 2] = v[:, None, None], v[None, :, None], v[None, None, :]
    want = (rgb[..., 0].astype(np.uint16) * W_R + rgb[..., 1].astype(np.uint16) * W_G
            + rgb[..., 2].astype(np.uint16) * W_B) >> SHIFT
    want = want.astype(np.uint8).reshape(-1)
    assert np.array_equal(to_grey(rgb.reshape(4096, 4096, 3))[0].reshape(-1), want)
    narrow = rgb.reshape(-1, 3)[:7 * 300_000].reshape(300_000, 7, 3)
    got = to_grey(narrow)[0]
    assert got.shape == (300_000, 7) and np.array_equal(got.reshape(-1), want[:got.size])
    view = rgb.reshape(4096, 4096, 3)[3:1000:2, 5:1001]
    want2 = want.reshape(4096, 4096)[3:1000:2, 5:1001]
    assert np.array_equal(to_grey(view)[0], want2)
    one = to_grey(rgb.reshape(4096, 4096, 3)[:1, :1])[0]
    assert one.shape == (1, 1) and one[0, 0] == 0


@pytest.mark.parametrize("bad", [
    np.zeros((4, 4), np.uint8), np.zeros((4, 4, 4), np.uint8), np.zeros((4, 4, 3), np.float32),
    np.zeros((0, 4, 3), np.uint8), [[1, 2, 3]],
])
def test_grey_rejects_bad_input(bad):
    with pytest.raises(ValueError):
        to_grey(bad)


@pytest.mark.parametrize("sigma", [0, 5, 12, 30])
def test_noise_sigma_estimate(sigma):
    from mobigrasp.host.vision.grey import noise_sigma
    rng = np.random.default_rng(sigma)
    y, x = np.mgrid[0:240, 0:320]
    smooth = 120 + 40 * np.sin(x / 40.0) * np.cos(y / 30.0)  # floor-like shading
    grey = np.clip(np.rint(smooth + rng.normal(0, sigma, smooth.shape)), 0, 255).astype(np.uint8)
    est, ops = noise_sigma(grey)
    assert abs(est - sigma) <= max(1.0, 0.15 * sigma)
    assert ops.pixels_read > 0
    with pytest.raises(ValueError):
        noise_sigma(np.zeros((4, 4, 3), np.uint8))
