"""Host-speed rewrites of detector steps give what the plain numpy code gave (the reference
implementations below are the earlier code, kept here as the definition)."""

from __future__ import annotations

import cv2
import numpy as np

from mobigrasp.host.vision import dark_blobs as db
from mobigrasp.host.vision import double_cross
from mobigrasp.host.vision.dual_plus import _solidity_pct


def _solidity_reference(sel: np.ndarray) -> int:
    contours, _ = cv2.findContours(sel.view(np.uint8), cv2.RETR_EXTERNAL,
                                   cv2.CHAIN_APPROX_SIMPLE)
    if not contours:
        return 0
    pts = np.concatenate(contours).reshape(-1, 2).astype(np.int64)
    corners = np.concatenate([pts, pts + [1, 0], pts + [0, 1], pts + [1, 1]])
    hull = cv2.convexHull(corners.astype(np.int32)).reshape(-1, 2).astype(np.int64)
    x, y = hull[:, 0], hull[:, 1]
    area2 = abs(int((x * np.roll(y, -1) - y * np.roll(x, -1)).sum()))
    if area2 == 0:
        return 0
    return 200 * int(sel.sum()) // area2


def _masks(n: int, seed: int):
    rng = np.random.default_rng(seed)
    for i in range(n):
        h, w = (int(v) for v in rng.integers(1, 40, 2))
        m = rng.random((h, w)) < rng.random()
        if i % 4 == 0:  # a "+" of random arm lengths and width
            m = np.zeros((h + 8, w + 8), bool)
            cy, cx = (h + 8) // 2, (w + 8) // 2
            t = int(rng.integers(1, 4))
            m[cy - t:cy + t + 1, 2:w + 6] = True
            m[2:h + 6, cx - t:cx + t + 1] = True
        if i % 5 == 0:  # a strided view, as a crop of the labels is
            m = np.pad(m, 3)[2:-1, 1:-2]
        yield m


def test_solidity_equals_the_numpy_reference():
    for sel in _masks(400, 1):
        assert _solidity_pct(sel)[0] == _solidity_reference(sel)


def test_nonzero_yx_is_numpy_nonzero():
    for sel in _masks(300, 2):
        ys, xs = db.nonzero_yx(sel)
        want_y, want_x = np.nonzero(sel)
        assert ys.dtype == xs.dtype == np.int64
        assert np.array_equal(ys, want_y) and np.array_equal(xs, want_x)


def test_moments_equal_the_pixel_sums():
    for i, sel in enumerate(_masks(200, 3)):
        x0, y0 = 3 * i, 7 + i
        ys, xs = np.nonzero(sel)
        xs, ys = xs.astype(np.int64) + x0, ys.astype(np.int64) + y0
        want = (len(xs), int(xs.sum()), int(ys.sum()), int((xs * xs).sum()),
                int((xs * ys).sum()), int((ys * ys).sum()))
        assert db.moments(sel, x0, y0) == want


def _downsample_reference(g: np.ndarray) -> np.ndarray:
    h, w = (g.shape[0] // 2) * 2, (g.shape[1] // 2) * 2
    s = g[0:h:2, 0:w:2].astype(np.uint16)
    s += g[1:h:2, 0:w:2]
    s += g[0:h:2, 1:w:2]
    s += g[1:h:2, 1:w:2]
    return ((s + 2) >> 2).astype(np.uint8)


def test_pyramid_level_is_the_rounded_2x2_mean():
    rng = np.random.default_rng(4)
    for i in range(300):
        h, w = (int(v) for v in rng.integers(2, 90, 2))
        g = rng.integers(0, 256, (h, w), dtype=np.uint8)
        if i % 3 == 0:
            g = (g // 64 * 85).astype(np.uint8)  # few levels: many sums at a rounding tie
        if i % 5 == 0:
            g = np.pad(g, 2)[1:-1, 2:]  # a strided view
        assert np.array_equal(double_cross._downsample(g), _downsample_reference(g))
    # every pair of first-row values with a few others, and the frame sizes of a run
    v = np.arange(256, dtype=np.uint8)
    g = np.zeros((512, 512), np.uint8)
    g[0::2, 0::2], g[0::2, 1::2] = v[:, None], v[None, :]
    for d in (0, 1, 2, 3, 128, 255):
        g[1::2, 0::2] = d
        g[1::2, 1::2] = (v[:, None].astype(np.int32) + d) % 256
        assert np.array_equal(double_cross._downsample(g), _downsample_reference(g))
    for shape in ((240, 320), (120, 160), (60, 80), (241, 321)):
        g = rng.integers(0, 256, shape, dtype=np.uint8)
        assert np.array_equal(double_cross._downsample(g), _downsample_reference(g))


def test_ring_words_and_pattern_equal_the_plain_forms():
    rng = np.random.default_rng(5)
    for k in (0, 1, 7, 500):
        bits = rng.random((k, double_cross.RING_N)) < 0.5
        packed = np.packbits(bits, axis=1, bitorder="little").astype(np.int64)
        want = np.zeros(k, np.int64)
        for b in range(packed.shape[1]):
            want |= packed[:, b] << (8 * b)
        got = double_cross.ring_codes(bits)
        assert got.dtype == np.int64 and np.array_equal(got, want)
    # random words, and every template with up to two points flipped (near the threshold)
    t = double_cross._TEMPLATES
    flips = [t ^ (1 << i) ^ (1 << j) for i in range(24) for j in range(i, 24)]
    codes = np.concatenate([rng.integers(0, 1 << 24, 100_000), t, *flips]).astype(np.int64)
    rises = np.bitwise_count(codes & ~double_cross._rot(codes, 1) & double_cross._MASK)
    dist = np.bitwise_count(codes[:, None] ^ t[None, :]).min(axis=1)
    want = (rises == 4) & (dist <= double_cross.RING_HAMMING)
    assert want.sum() > 100
    assert np.array_equal(double_cross.ring_pattern_ok(codes), want)
