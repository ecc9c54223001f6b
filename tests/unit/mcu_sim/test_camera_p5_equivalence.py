"""The camera's shortcuts of perf round 5 give bit for bit what the general expressions give.

- camera_linalg: the LAPACK gufuncs called directly equal np.linalg.svd / inv; column copies
  equal np.column_stack; a singular matrix still raises.
- texture_plan's Jacobian in plain floats, its cached patch matrix and the depth-sort norm equal
  the numpy expressions they replace.
- A texture that covers the frame is written straight into it: the same pixels as the masked
  copy and rim blend of the general path (every alpha is 255 there).
- The rim blend by flat index equals the per-pixel fancy-indexed blend.
"""

from __future__ import annotations

import math
import warnings

import cv2
import numpy as np
import pytest

from mobigrasp.mcu_sim.world import camera as cam
from mobigrasp.mcu_sim.world import camera_linalg as la
from mobigrasp.mcu_sim.world import markers as mk
from mobigrasp.mcu_sim.world.camera import Intrinsics, look_rotation, render_clean
from mobigrasp.mcu_sim.world.camera_scene import Scene, Target

INTR = Intrinsics()


def _random_matrices(shape, n=400, seed=7):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        scale = 10.0 ** rng.uniform(-6, 6)
        yield rng.standard_normal(shape) * scale


def test_svd_values_equal_numpy():
    for a in _random_matrices((2, 2)):
        assert la.svd_values(a) == np.linalg.svd(a, compute_uv=False).tolist()


def test_inv_equals_numpy_and_still_raises_on_a_singular_matrix():
    for a in _random_matrices((3, 3)):
        assert np.array_equal(la.inv(a), np.linalg.inv(a))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the error alone, no RuntimeWarning of the fast path
        with pytest.raises(np.linalg.LinAlgError):
            la.inv(np.array([[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]]))


def test_columns3_equals_column_stack():
    for a in _random_matrices((3, 3)):
        got = la.columns3(a[0], a[1], a[2])
        want = np.column_stack([a[0], a[1], a[2]])
        assert np.array_equal(got, want) and got.flags.c_contiguous and got.dtype == want.dtype


def test_texel_jacobian_equals_the_array_expression():
    for M in _random_matrices((3, 3)):
        texel = float(abs(M[0, 0])) * 1e-3 + 1e-4
        w = M[2, 2]
        want = np.column_stack([(M[:2, k] * w - M[:2, 2] * M[2, k]) / w**2
                                for k in (0, 1)]) * texel
        assert np.array_equal(cam._texel_jacobian(M, texel), want)


def test_patch_matrix_is_the_product_it_caches():
    for M in _random_matrices((3, 3), n=50):
        for ss, x0, y0 in ((1, 0, 0), (3, 17, 200), (4, 319, 5)):
            T = np.array([[1.0, 0, -x0], [0, 1.0, -y0], [0, 0, 1.0]])
            want = cam._supersample_matrix(ss) @ T @ M
            assert np.array_equal(cam._patch_matrix(ss, x0, y0) @ M, want)


def test_sort_norm_equals_linalg_norm():
    for a in _random_matrices((3,)):
        assert cam._norm(a) == float(np.linalg.norm(a))


@pytest.mark.parametrize("yaw", [0.0, 0.9])
def test_frame_covering_texture_written_directly_equals_the_general_path(yaw, monkeypatch):
    scene = Scene(target=Target("radial-symbol", 0.4, -0.3, 0.5), seed=4)
    R = look_rotation(yaw, -math.pi / 2 + 0.02, 0.1)
    taken = []
    real = cam._Painter._draw_texture

    def spy(self, *plan, opaque=False):
        if opaque:
            x0, y0, x1, y1 = plan[2]
            # the general path on a copy of the frame as it is now
            general = self.img.copy()
            keep, self.img = self.img, general
            real(self, *plan)
            self.img = keep
            src, H, ss = plan[0], plan[1], plan[3]
            warped = _warp(src, H, ss, x1 - x0, y1 - y0)
            assert warped[..., 3].min() == 255  # what covers_frame promises
            real(self, *plan, opaque=True)
            assert np.array_equal(self.img, general)
            taken.append(True)
            return
        real(self, *plan)

    monkeypatch.setattr(cam._Painter, "_draw_texture", spy)
    for height_m in np.arange(0.10, 0.22, 0.01):
        pos = (0.4, -0.3, mk.OBJECT_TOP_Z_M + height_m)
        render_clean(scene, pos, R, INTR)
    assert taken  # the close poses took the direct write


def _warp(src, H, ss, w, h):
    """The warped (and block-averaged) RGBA patch _draw_texture paints."""
    warped = cv2.warpPerspective(src, H, (ss * w, ss * h), flags=cv2.INTER_LINEAR,
                                 borderMode=cv2.BORDER_CONSTANT, borderValue=(0, 0, 0, 0))
    if ss > 1:
        warped = cv2.resize(warped, (w, h), interpolation=cv2.INTER_AREA)
    return warped


def test_rim_blend_by_flat_index_equals_fancy_indexing():
    rng = np.random.default_rng(3)
    for _ in range(60):
        img = rng.integers(0, 256, (INTR.height, INTR.width, 3), dtype=np.uint8)
        h, w = int(rng.integers(1, INTR.height)), int(rng.integers(1, INTR.width))
        y0, x0 = int(rng.integers(0, INTR.height - h + 1)), int(rng.integers(0, INTR.width - w + 1))
        rgb = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
        alpha = rng.choice(np.array([0, 1, 2, 127, 128, 253, 254, 255], np.uint8), (h, w))
        rim_xy = cv2.findNonZero(cv2.inRange(alpha, 1, 254))
        if rim_xy is None:
            continue
        rim_xy = rim_xy.reshape(-1, 2)
        want = img.copy()
        roi = want[y0:y0 + h, x0:x0 + w]
        rim = (rim_xy[:, 1], rim_xy[:, 0])
        a = alpha[rim].astype(np.uint16)[:, None]
        roi[rim] = ((roi[rim].astype(np.uint16) * (255 - a) + rgb[rim] * a + 127)
                    // 255).astype(np.uint8)
        cam._blend_rim(img, x0, y0, rgb, alpha, rim_xy)
        assert np.array_equal(img, want)
