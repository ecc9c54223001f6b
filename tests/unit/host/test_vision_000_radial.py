"""Radial symbol detector of paper 000 on frames from the camera renderer (small fixed sets)."""

import math

import numpy as np
import pytest
from clipped_frame import clipped_far_frame

from mobigrasp.host.vision import dark_blobs as db
from mobigrasp.host.vision import radial_symbol as rs
from mobigrasp.host.vision.grey import to_grey
from mobigrasp.host.vision.radial_symbol import L_MM, detect_radial_symbol
from mobigrasp.mcu_sim.world import camera_views as views
from mobigrasp.mcu_sim.world.camera import CameraOptions, render

DEGRADED = (CameraOptions(noise_std=8.0, blur_px=2.0, brightness=0.7),
            CameraOptions(noise_std=8.0, blur_px=2.0, brightness=1.3))


def _frames(n, seed, degraded=False, sampler=views.radial_far):
    rng = np.random.default_rng(seed)
    for i in range(n):
        v = sampler(rng)
        opt = DEGRADED[i % 2] if degraded else CameraOptions()
        yield v, render(v.scene, v.cam_pos_w, v.R_wc, v.intr, opt, np.random.default_rng(i))


def test_clean_frames_meet_the_issue_thresholds():
    dist_err, bear_err, found, n = [], [], 0, 40
    for v, img in _frames(n, seed=11):
        r, ops = detect_radial_symbol(img)
        assert ops.cycles() > img.shape[0] * img.shape[1]  # it is charged for reading the frame
        if r is None:
            continue
        found += 1
        dist_err.append(abs(r.y_oc_mm - v.truth["y_oc_mm"]) / v.truth["y_oc_mm"])
        bear = math.degrees(math.atan2(r.x_oc_mm, r.y_oc_mm))
        bear_err.append(abs(bear - v.truth["bearing_deg"]))
    assert found >= 0.99 * n
    assert np.median(dist_err) <= 0.02 and np.percentile(dist_err, 95) <= 0.05
    assert max(bear_err) <= 0.5


def test_degraded_frames_are_still_found():
    results = [detect_radial_symbol(img)[0] for _, img in _frames(30, seed=12, degraded=True)]
    assert sum(r is not None for r in results) >= 0.95 * len(results)


def test_no_detection_without_the_symbol():
    for i, (_, img) in enumerate(_frames(25, seed=13, degraded=False, sampler=views.empty)):
        assert detect_radial_symbol(img)[0] is None, f"false positive on empty frame {i}"
    for _, img in _frames(15, seed=14, degraded=True, sampler=views.empty):
        assert detect_radial_symbol(img)[0] is None
    flat = np.full((240, 320, 3), 128, np.uint8)
    assert detect_radial_symbol(flat)[0] is None


def test_position_follows_the_paper_formulas():
    v, img = next(_frames(1, seed=15))
    r, _ = detect_radial_symbol(img, f_px=611, u0_px=160, v0_px=120)
    assert r is not None
    y = L_MM * 611 / (r.diameter_q4 / 16)  # float reference of Y_oc = L f / (d_p + d_rp)
    assert abs(r.y_oc_mm - y) <= 1
    assert abs(r.x_oc_mm - (160 - r.u_q4 / 16) * r.y_oc_mm / 611) <= 1
    assert abs(r.z_oc_mm - (120 - r.v_q4 / 16) * r.y_oc_mm / 611) <= 1
    assert abs(r.z_oc_mm - v.truth["z_oc_mm"]) <= 0.03 * v.truth["y_oc_mm"]


def test_a_clipping_gain_keeps_the_far_reading(monkeypatch):
    """At camera gain 1.7 the card clips at 255: the thresholds that follow the gain (the
    median level globally, a third local fraction) read the symbol 1.12 m off, where the
    thresholds of an unclipped frame (45 % of the clipped level, locally 1/2 and 1/3) do not."""
    v, img = clipped_far_frame()
    grey, _ = to_grey(img)
    assert np.count_nonzero(grey == 255) >= grey.size // db.BRIGHT_FRACTION_DEN  # it clips
    r, _ = detect_radial_symbol(img)
    assert r is not None
    assert abs(r.y_oc_mm - v.truth["y_oc_mm"]) <= 0.05 * v.truth["y_oc_mm"]
    monkeypatch.setattr(db, "CLIP_MEDIAN_NUM", 0)  # the threshold of an unclipped frame
    monkeypatch.setattr(rs, "CLIPPED_SUM", 3 * 255 + 1)  # no third local fraction
    db.forget_front_end()  # the front end computed again, with the unclipped threshold
    assert detect_radial_symbol(img)[0] is None


def test_unclipped_thresholds_are_45_percent_of_the_bright_level():
    """With fewer than 1/500 of the pixels at 255 the threshold is the bright level's 45 %
    clamped to 40..130, whatever the median (the frames of an unclipped camera keep it)."""
    rng = np.random.default_rng(4)
    for i in range(200):
        h, w = (int(v) for v in rng.integers(16, 90, 2))
        hi = int(rng.integers(30, 256))
        grey = rng.integers(0, hi, (h, w), dtype=np.uint8)
        if i % 2:  # some pixels at 255, under 1/500 of them
            grey.ravel()[:grey.size // db.BRIGHT_FRACTION_DEN - 1] = 255
        flat = np.sort(grey.ravel())[::-1]
        bright = int(flat[grey.size // db.BRIGHT_FRACTION_DEN - 1]) if grey.size >= 500 else 255
        _, t, _ = db.dark_mask(grey)
        assert t == min(db.THRESH_MAX, max(db.THRESH_MIN, bright * 45 // 100))


@pytest.mark.parametrize("bad", [
    np.zeros((240, 320, 3), np.float32),
    np.zeros((240, 320), np.uint8),
    np.zeros((240, 320, 4), np.uint8),
    np.zeros((8, 8, 3), np.uint8),
    [[0, 0, 0]],
])
def test_bad_input_is_a_value_error(bad):
    with pytest.raises(ValueError):
        detect_radial_symbol(bad)
