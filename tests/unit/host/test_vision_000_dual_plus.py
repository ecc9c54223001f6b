"""Dual "+" detector of paper 000 on frames from the camera renderer (small fixed sets)."""

import math

import numpy as np
import pytest

from mobigrasp.host.vision.dual_plus import D_ACT_DMM, detect_dual_plus
from mobigrasp.mcu_sim.world import camera_views as views
from mobigrasp.mcu_sim.world.camera import CameraOptions, render

DEGRADED = (CameraOptions(noise_std=8.0, blur_px=2.0, brightness=0.7),
            CameraOptions(noise_std=8.0, blur_px=2.0, brightness=1.3))


def _frames(n, seed, degraded=False, sampler=views.dual_plus):
    rng = np.random.default_rng(seed)
    for i in range(n):
        v = sampler(rng)
        opt = DEGRADED[i % 2] if degraded else CameraOptions()
        yield v, render(v.scene, v.cam_pos_w, v.R_wc, v.intr, opt, np.random.default_rng(i))


def _alpha_mrad(v):
    return int(round(1000 * v.truth["alpha_rad"]))


def test_clean_frames_meet_the_issue_thresholds():
    dist_err, raw_err, centre_err, n = [], [], [], 30
    for v, img in _frames(n, seed=21):
        r, ops = detect_dual_plus(img, alpha_mrad=_alpha_mrad(v))
        assert r is not None
        assert ops.cycles() > img.shape[0] * img.shape[1]
        truth = v.truth["y_oc_mm"]
        dist_err.append(abs(r.dist_mm - truth) / truth)
        raw_err.append(abs(r.dist_raw_mm - truth) / truth)
        uv = v.truth["plus_uv"][np.argsort(v.truth["plus_uv"][:, 0])]
        got = np.array([[r.u1_q4, r.v1_q4], [r.u2_q4, r.v2_q4]]) / 16
        centre_err.append(np.abs(got - uv).max())
    assert np.median(dist_err) <= 0.02 and np.percentile(dist_err, 95) <= 0.05
    assert max(centre_err) <= 1.0
    # the foreshortening correction is what makes the 5 % bound: the paper's raw formula misses
    assert np.percentile(raw_err, 95) > 0.05
    # bearing of the pair's midpoint from its pixels, against the projected truth
    for v, img in _frames(10, seed=22):
        r, _ = detect_dual_plus(img, alpha_mrad=_alpha_mrad(v))
        got = math.atan2(160 - (r.u1_q4 + r.u2_q4) / 32, 611)
        want = math.atan2(160 - v.truth["plus_uv"][:, 0].mean(), 611)
        assert abs(math.degrees(got - want)) <= 0.5


def test_degraded_frames_are_still_found():
    results = [detect_dual_plus(img)[0] for _, img in _frames(30, seed=23, degraded=True)]
    assert sum(r is not None for r in results) >= 0.95 * len(results)


def test_no_detection_without_the_symbol():
    for i, (_, img) in enumerate(_frames(25, seed=24, sampler=views.empty)):
        assert detect_dual_plus(img)[0] is None, f"false positive on empty frame {i}"
    for _, img in _frames(15, seed=25, degraded=True, sampler=views.empty):
        assert detect_dual_plus(img)[0] is None
    assert detect_dual_plus(np.full((240, 320, 3), 200, np.uint8))[0] is None


def test_position_follows_the_paper_formulas():
    v, img = next(_frames(1, seed=26))
    alpha = _alpha_mrad(v)
    r, _ = detect_dual_plus(img, alpha_mrad=alpha, f_px=611, u0_px=160)
    d_pixel = math.hypot((r.u1_q4 - r.u2_q4) / 16, (r.v1_q4 - r.v2_q4) / 16)
    assert abs(r.d_pixel_q4 / 16 - d_pixel) <= 1 / 16
    assert abs(r.dist_raw_mm - D_ACT_DMM / 10 * 611 / (r.d_pixel_q4 / 16)) <= 1
    assert abs(r.dist_mm - D_ACT_DMM / 10 * 611 / (r.d_eff_q4 / 16)) <= 1
    a = alpha / 1000
    assert abs(r.x_oc_mm - r.dist_mm * math.cos(a)) <= 1
    assert abs(r.y_oc_mm - r.dist_mm * math.sin(a)) <= 1
    assert abs(r.z_oc_mm - r.dist_mm * (160 - (r.u1_q4 + r.u2_q4) / 32) / 611) <= 1


@pytest.mark.parametrize("bad", [
    np.zeros((240, 320, 3), np.int16),
    np.zeros((240, 320), np.uint8),
    "frame",
])
def test_bad_input_is_a_value_error(bad):
    with pytest.raises(ValueError):
        detect_dual_plus(bad)
    with pytest.raises(ValueError):
        detect_dual_plus(np.zeros((240, 320, 3), np.uint8), alpha_mrad=1.5)


def _plus_pair_frame(scale_b: float) -> np.ndarray:
    """Two "+" on white, 150 px apart, the right one ``scale_b`` times the left one's size."""
    img = np.full((240, 320, 3), 235, np.uint8)
    for cu, size in ((90, 40.0), (240, 40.0 * scale_b)):
        half, w = int(round(size / 2)), int(round(size * 6 / 17 / 2))
        img[120 - w:120 + w + 1, cu - half:cu + half + 1] = 20
        img[120 - half:120 + half + 1, cu - w:cu + w + 1] = 20
    return img


@pytest.mark.parametrize("scale_b,found", [(1.0, True), (1.3, True), (1.38, True),
                                           (1.5, False), (1.7, False)])
def test_a_pair_differing_in_size_up_to_two_to_one_is_one_pair(scale_b, found):
    """A pair along the line of sight seen steeply from close (001's look before the grasp)
    differs ~1.7:1 in area; beyond 2:1 the two are not one pair (areas scale as scale_b**2)."""
    res, _ = detect_dual_plus(_plus_pair_frame(scale_b))
    assert (res is not None) == found, res
