"""Single "+" spoke detector of paper 000 (Fig. 3) on frames from the camera renderer."""

import math

import numpy as np
import pytest

from mobigrasp.host.vision.spoke import K_S, Spoke, detect_spoke, grasp_ready
from mobigrasp.mcu_sim.world import camera_views as views
from mobigrasp.mcu_sim.world.camera import CameraOptions, render

DEGRADED = (CameraOptions(noise_std=8.0, blur_px=2.0, brightness=0.7),
            CameraOptions(noise_std=8.0, blur_px=2.0, brightness=1.3))


def _frames(n, seed, degraded=False, sampler=views.spoke):
    rng = np.random.default_rng(seed)
    for i in range(n):
        v = sampler(rng)
        opt = DEGRADED[i % 2] if degraded else CameraOptions()
        yield v, render(v.scene, v.cam_pos_w, v.R_wc, v.intr, opt, np.random.default_rng(i))


def test_slope_and_width_on_clean_frames():
    n = 30
    for v, img in _frames(n, seed=31):
        r, ops = detect_spoke(img)
        assert r is not None
        assert ops.cycles() > img.shape[0] * img.shape[1]
        assert len(r.points_q4) >= 6 and len(r.points_q4) <= 2 * K_S
        assert abs(r.angle_mrad * 0.18 / math.pi - v.truth["angle_deg"]) <= 0.5
        assert abs(r.width_q4 / 16 - v.truth["width_px"]) <= 0.05 * v.truth["width_px"]
        u, w = v.truth["centre_uv"]
        assert abs(r.u_c_q4 / 16 - u) <= 1.0 and abs(r.v_c_q4 / 16 - w) <= 1.0
        # the slope is the tangent of the angle, in Q12
        assert abs(r.slope_q12 - 4096 * math.tan(r.angle_mrad / 1000)) <= 0.01 * 4096


def test_degraded_frames_are_still_measured():
    got = [(v, detect_spoke(img)[0]) for v, img in _frames(30, seed=32, degraded=True)]
    found = [(v, r) for v, r in got if r is not None]
    assert len(found) >= 0.95 * len(got)
    errs = [abs(r.angle_mrad * 0.18 / math.pi - v.truth["angle_deg"]) for v, r in found]
    assert np.percentile(errs, 95) <= 0.5


def test_no_spoke_without_a_plus():
    for i, (_, img) in enumerate(_frames(25, seed=33, sampler=views.empty)):
        assert detect_spoke(img)[0] is None, f"false positive on empty frame {i}"
    for _, img in _frames(15, seed=34, degraded=True, sampler=views.empty):
        assert detect_spoke(img)[0] is None


def test_grasp_ready_is_the_papers_rule():
    s = Spoke(0, 0, (), 0, 0, 16 * 30)
    assert grasp_ready(s)
    assert not grasp_ready(Spoke(0, 0, (), 200, 50, 16 * 30))  # k_T != 0
    assert not grasp_ready(Spoke(0, 0, (), 0, 0, 16 * 19))  # too far: w_T < w_min
    assert not grasp_ready(Spoke(0, 0, (), 0, 0, 16 * 41))  # too near: w_T > w_max
    # the width window of 000 is met in the range the marker is drawn for (docs/markers.md)
    widths = [v.truth["width_px"] for v, _ in _frames(10, seed=35)]
    assert all(20 <= w <= 40 for w in widths)


@pytest.mark.parametrize("bad", [
    np.zeros((240, 320, 3), np.float64),
    np.zeros((240, 320, 1), np.uint8),
    None,
])
def test_bad_input_is_a_value_error(bad):
    with pytest.raises(ValueError):
        detect_spoke(bad)
