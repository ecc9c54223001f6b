"""The host-speed shortcuts of the vision front end give exactly what the plain calls give:
cropped labelling (host.vision.dark_blobs._label_cropped), the reused front end of a frame and
the ring test's label mask (host.vision.radial_symbol._label_mask)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host.vision import dark_blobs as db
from mobigrasp.host.vision.grey import W_B, W_G, W_R, to_grey
from mobigrasp.host.vision.radial_symbol import _label_mask


@st.composite
def masks(draw):
    h, w = draw(st.integers(16, 120)), draw(st.integers(16, 160))
    bh, bw = draw(st.integers(1, h)), draw(st.integers(1, w))
    y, x = draw(st.integers(0, h - bh)), draw(st.integers(0, w - bw))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    m = np.zeros((h, w), np.uint8)
    m[y:y + bh, x:x + bw] = rng.random((bh, bw)) < draw(st.floats(0.0, 1.0))
    return m


@examples(150)
@given(masks())
def test_cropped_labelling_equals_opencv_on_whole_mask(mask):
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8,
                                                           ltype=cv2.CV_32S)
    n2, labels2, stats2 = db._label_cropped(mask)
    assert n2 == n
    assert np.array_equal(labels2, labels)
    assert np.array_equal(stats2, stats)


def test_cropped_labelling_of_print_in_a_corner():
    # two components near the bottom right: odd box offsets, background stats from outside
    mask = np.zeros((240, 320), np.uint8)
    mask[201:207, 251:260] = 1
    mask[215:230, 265:270] = 1
    mask[220, 300] = 1
    want = cv2.connectedComponentsWithStats(mask, connectivity=8, ltype=cv2.CV_32S)
    got = db._label_cropped(mask)
    assert got[0] == want[0] == 4
    assert np.array_equal(got[1], want[1]) and np.array_equal(got[2], want[2])


def test_grey_matches_the_integer_formula():
    rgb = np.random.default_rng(3).integers(0, 256, (24, 40, 3), dtype=np.uint8)
    grey, _ = to_grey(rgb)
    want = (rgb[..., 0].astype(np.int32) * W_R + rgb[..., 1].astype(np.int32) * W_G
            + rgb[..., 2].astype(np.int32) * W_B) >> 8
    assert np.array_equal(grey, want.astype(np.uint8))
    # a strided view (a crop of a bigger frame) gives the same as its copy
    big = np.random.default_rng(4).integers(0, 256, (60, 80, 3), dtype=np.uint8)
    assert np.array_equal(to_grey(big[5:40, 7:70])[0], to_grey(big[5:40, 7:70].copy())[0])


def test_front_end_reused_only_for_the_same_pixels_and_read_only():
    rng = np.random.default_rng(5)
    a = rng.integers(0, 256, (48, 64, 3), dtype=np.uint8)
    first = db.dark_components(a, "t")
    again = db.dark_components(a.copy(), "t")
    assert again[0] is first[0] and again[5] == first[5] and again[5] is not first[5]
    with pytest.raises(ValueError):
        first[3][0, 0] = 7  # the shared labels cannot be changed by a detector
    b = a.copy()
    b[10, 10] = 255 - b[10, 10]
    other = db.dark_components(b, "t")
    assert other[0] is not first[0]
    assert np.array_equal(other[0], to_grey(b)[0])


def test_block_labelling_numbers_components_as_the_default():
    # BBDT (dark_blobs._CCL_8) instead of OpenCV's default: same labels and stats on frames of
    # blobs, thin strokes and rings at odd offsets (first 2x2 block of each component decides)
    rng = np.random.default_rng(6)
    for i in range(24):
        noise = (rng.random((240, 320)) < (0.02 + 0.04 * (i % 6))).astype(np.uint8)
        k = 1 + i % 4
        mask = cv2.dilate(noise, np.ones((k, k + i % 3), np.uint8))
        cv2.circle(mask, (int(rng.integers(40, 280)), int(rng.integers(40, 200))), 30, 1, 1 + i % 3)
        want = cv2.connectedComponentsWithStats(mask, connectivity=8, ltype=cv2.CV_32S)
        got = cv2.connectedComponentsWithStatsWithAlgorithm(mask, 8, cv2.CV_32S, db._CCL_8)
        assert got[0] == want[0]
        assert np.array_equal(got[1], want[1]) and np.array_equal(got[2], want[2])


@pytest.mark.parametrize("n_labels", [1, 2, 5, 255, 256, 257, 1000])
def test_label_mask_is_the_gather_for_any_number_of_labels(n_labels):
    # radial_symbol._label_mask: a byte table look-up up to 256 labels, numpy's gather above
    rng = np.random.default_rng(n_labels)
    lab = rng.integers(0, n_labels, (37, 53)).astype(np.int32)
    for chosen in (rng.random(n_labels) < 0.5, np.zeros(n_labels, bool), np.ones(n_labels, bool)):
        got = _label_mask(lab, chosen)
        assert got.dtype == bool and got.shape == lab.shape
        assert np.array_equal(got, chosen[lab])
