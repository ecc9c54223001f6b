"""The held-object fill detector on rendered frames: the camera inside the object it holds,
under the harshest camera of the random scenes, against views of the scene around it."""

import math

import numpy as np
import pytest

from mobigrasp.host.vision.held_fill import (
    FILL_MIN_PERMILLE,
    body_brown,
    detect_held_fill,
    red_paint,
)
from mobigrasp.mcu_sim.world import markers as mk
from mobigrasp.mcu_sim.world.camera import (
    CameraOptions,
    Intrinsics,
    apply_options,
    look_rotation,
    render_clean,
)
from mobigrasp.mcu_sim.world.camera_scene import Scene, Target

INTR = Intrinsics(f_px=611, u0_px=160, v0_px=120)


@pytest.mark.parametrize("kind", ["radial-symbol", "red-cylinder"])
@pytest.mark.parametrize(("noise", "brightness", "blur"), [(0.0, 1.0, 0.0), (12.0, 0.45, 3.0),
                                                           (12.0, 1.8, 3.0)])
def test_the_camera_inside_a_held_object_sees_it_fill_the_frame(kind, noise, brightness, blur):
    grip = 0.08 if kind == "radial-symbol" else 0.10
    scene = Scene(Target(kind, 0.3, 0.1, 0.4, z_m=0.15), seed=3)
    pos = (0.3, 0.1, 0.15 + grip)  # the fingertip at the grasp point, lifted 0.15 m
    rng = np.random.default_rng(5)
    for pitch in (-math.pi / 2, -0.8, 0.0):
        img = apply_options(render_clean(scene, pos, look_rotation(0.2, pitch), INTR),
                            CameraOptions(noise_std=noise, blur_px=blur, brightness=brightness),
                            rng)
        res, ops = detect_held_fill(img)
        assert res is not None and res.fill_permille >= FILL_MIN_PERMILLE
        assert ops.pixels_read > 0
        assert red_paint(res.rgb) == (kind == "red-cylinder")
        assert body_brown(res.rgb) == (kind == "radial-symbol")
        if kind == "radial-symbol":  # the body's brown, scaled by the brightness
            assert abs(res.rgb[0] - min(255, mk.BODY_RGB[0] * brightness)) < 25


@pytest.mark.parametrize("kind", ["radial-symbol", "red-cylinder"])
@pytest.mark.parametrize("brightness", [0.45, 1.0, 1.8])
def test_views_of_the_scene_are_never_the_object_filling_the_frame(kind, brightness):
    """The object standing ahead, below, beside, the floor: a frame filled by the floor may
    come, never one of the object's colour. (Right above the standing cylinder, within ~0.1 m
    of its top, its face fills the frame too: the grasp check asks for two fingertip places
    25 mm or more apart, which a standing object cannot both fill, host/task/grasp.py.)"""
    rng = np.random.default_rng(2)
    for seed in (1, 3, 8):
        scene = Scene(Target(kind, 0.3, 0.0, math.pi), seed=seed)
        for pos, yaw, pitch in (((0.0, 0.0, 0.2), 0.0, -0.5), ((0.3, 0.0, 0.35), 0.0, -1.5),
                                ((0.3, 0.04, 0.16), 0.0, -math.pi / 2),
                                ((0.0, 0.0, 0.25), 2.0, -1.0)):
            img = apply_options(render_clean(scene, pos, look_rotation(yaw, pitch), INTR),
                                CameraOptions(noise_std=12.0, brightness=brightness), rng)
            res, _ = detect_held_fill(img)
            assert res is None or not (body_brown(res.rgb) or red_paint(res.rgb)), (seed, pos)


def test_half_a_frame_is_not_filled_and_bad_input_is_refused():
    img = np.zeros((240, 320, 3), np.uint8)
    img[:, :170] = (200, 30, 30)
    assert detect_held_fill(img)[0] is None
    img[:, :300] = (200, 30, 30)
    res, _ = detect_held_fill(img)
    assert res is not None and res.rgb == (200, 30, 30)
    with pytest.raises(ValueError):
        detect_held_fill(np.zeros((240, 320), np.uint8))
