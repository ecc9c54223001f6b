"""Host-speed rewrites of detector steps give what the plain numpy code gave (the reference
implementations below are the earlier code, kept here as the definition)."""

from __future__ import annotations

import cv2
import numpy as np

from host.vision import dark_blobs as db
from host.vision.dual_plus import _solidity_pct


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
