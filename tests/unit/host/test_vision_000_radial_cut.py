"""The radial symbol cut by the frame's border (host/vision/radial_symbol.py
detect_radial_cut) on frames from the camera renderer: a symbol near the camera with its centre
beyond the left or right border, none on frames without the symbol, and the whole symbol read
as a symbol, not as a cut."""

import numpy as np
import pytest

from mobigrasp.host.vision.radial_symbol import detect_radial_cut, detect_radial_symbol
from mobigrasp.mcu_sim.world import camera_views as views
from mobigrasp.mcu_sim.world.camera import CameraOptions, render


def _near(rng: np.random.Generator, du_px: float, opt: CameraOptions) -> np.ndarray:
    v = views.radial_cut(rng, du_px)
    return render(v.scene, v.cam_pos_w, v.R_wc, v.intr, opt, np.random.default_rng(0))


@pytest.mark.parametrize("opt", [CameraOptions(), CameraOptions(noise_std=12.0, blur_px=3.0,
                                                                  brightness=0.45)])
@pytest.mark.parametrize("side", [-1, 1])
def test_a_near_symbol_beyond_the_border_is_cut_at_that_side(side, opt):
    rng = np.random.default_rng(40 + side)
    found = 0
    for _ in range(10):
        rgb = _near(rng, side * rng.uniform(165, 200), opt)
        cut, ops = detect_radial_cut(rgb)
        assert detect_radial_symbol(rgb)[0] is None  # not read whole
        assert ops.cycles() > rgb.shape[0] * rgb.shape[1]  # the front end is charged
        if cut is None:
            continue
        found += 1
        assert cut.side == side and cut.w >= 64, cut
        assert (cut.x == 0) if side < 0 else (cut.x + cut.w == rgb.shape[1])
    assert found >= 8


def test_clutter_is_seldom_a_cut():
    """Frames of ten clutter objects and no symbol (coloured boxes, cylinders, flat shapes
    touching the border): at most 2 of 100 give a cut (a back-off at the start is bounded)."""
    rng = np.random.default_rng(44)
    cuts = 0
    for i in range(100):
        v = views.empty(rng)
        img = render(v.scene, v.cam_pos_w, v.R_wc, v.intr, CameraOptions(),
                     np.random.default_rng(i))
        cuts += detect_radial_cut(img)[0] is not None
    assert cuts <= 2
    assert detect_radial_cut(np.full((240, 320, 3), 128, np.uint8))[0] is None


def test_a_symbol_in_the_middle_of_the_frame_is_not_cut():
    rng = np.random.default_rng(45)
    for _ in range(6):
        v = views.radial_far(rng, clutter=0)
        img = render(v.scene, v.cam_pos_w, v.R_wc, v.intr, CameraOptions(),
                     np.random.default_rng(1))
        if detect_radial_symbol(img)[0] is not None:
            cut = detect_radial_cut(img)[0]
            assert cut is None or cut.w < img.shape[1]  # a symbol read whole is no cut of it
