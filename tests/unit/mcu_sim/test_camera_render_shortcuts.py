"""The renderer's speed shortcuts draw what the plain painter's algorithm draws.

- The floor: warped from a mosaic for the near rows and remapped at float64 texel coordinates
  for the far rows; compared with a float64 bilinear reference of the repeating tile.
- A texture opaque over the whole frame skips everything painted before it; compared with a
  frame painted without the shortcut.
"""

import math

import numpy as np
import pytest

from mobigrasp.mcu_sim.world import camera as cam
from mobigrasp.mcu_sim.world import camera_ground as ground
from mobigrasp.mcu_sim.world import markers as mk
from mobigrasp.mcu_sim.world.camera import Intrinsics, look_rotation, render_clean
from mobigrasp.mcu_sim.world.camera_scene import Obstacle, Scene, Target, solids_of_scene

INTR = Intrinsics()


def _floor_reference(seed, pos, R, intr=INTR):
    """Bilinear sample of the repeating floor tile at every pixel (float64), NaN off the floor."""
    tex = mk.ground_texture(seed)
    tile = tex.levels[0][..., :3].astype(np.float64)
    n = tile.shape[0]
    u, v = np.meshgrid(np.arange(intr.width, dtype=float), np.arange(intr.height, dtype=float))
    rays = np.stack([(u - intr.u0_px) / intr.f_px, (v - intr.v0_px) / intr.f_px,
                     np.ones_like(u)], axis=-1) @ np.asarray(R).T
    with np.errstate(divide="ignore", invalid="ignore"):
        s = -pos[2] / rays[..., 2]
    on_floor = rays[..., 2] < -0.004 * np.linalg.norm(rays, axis=-1) - 1e-3
    x, y = pos[0] + s * rays[..., 0], pos[1] + s * rays[..., 1]
    # texel i has its centre at -h + (i + 0.5) t about any tile centre (a multiple of 2h)
    t, h = tex.texel_m, tex.half_m
    col = np.where(on_floor, (x + h) / t - 0.5, 0.0)
    row = np.where(on_floor, (h - y) / t - 0.5, 0.0)
    c0, r0 = np.floor(col), np.floor(row)
    fc, fr = (col - c0)[..., None], (row - r0)[..., None]
    c0, r0 = c0.astype(np.int64) % n, r0.astype(np.int64) % n
    c1, r1 = (c0 + 1) % n, (r0 + 1) % n
    ref = ((tile[r0, c0] * (1 - fc) + tile[r0, c1] * fc) * (1 - fr)
           + (tile[r1, c0] * (1 - fc) + tile[r1, c1] * fc) * fr)
    ref[~on_floor] = np.nan
    return ref, s


@pytest.mark.parametrize("pose", [
    ((0.3, -0.2, 0.40), (0.4, -math.pi / 2 + 0.05, 0.0)),   # straight down: near floor only
    ((1.7, 2.9, 0.26), (2.1, -0.05, 0.0)),                  # near the horizon: far rows too
    ((-3.1, 0.4, 0.30), (-0.7, -0.12, 0.35)),               # rolled horizon
])
def test_floor_matches_a_float64_bilinear_reference(pose):
    pos, (yaw, pitch, roll) = pose
    R = look_rotation(yaw, pitch, roll)
    img = render_clean(Scene(seed=5), pos, R, INTR).astype(np.float64)
    ref, dist = _floor_reference(5, pos, R)
    # a pixel far away is minified ~100x: its sample is chaotic in the 4th digit of the
    # coordinate, so the comparison is limited to floor closer than 15 m
    ok = ~np.isnan(ref[..., 0]) & (dist < 15.0)
    assert ok.mean() > 0.3
    diff = np.abs(img[ok] - ref[ok])
    assert diff.max() <= 1.5
    assert diff.mean() < 0.55


def test_far_floor_rows_are_drawn_and_sky_is_sky():
    pos, R = (0.0, 0.0, 0.3), look_rotation(0.3, -0.02, 0.0)
    img = render_clean(Scene(seed=2), pos, R, INTR)
    ref, _ = _floor_reference(2, pos, R)
    floor = ~np.isnan(ref[..., 0])
    horizon_row = int(np.flatnonzero(floor.any(axis=1))[0])
    # rows just below the horizon are floor far beyond the mosaic: drawn, not left empty
    band = img[horizon_row + 2:horizon_row + 12]
    assert np.abs(band.astype(int) - np.array(ground.SKY_RGB)).sum(axis=-1).min() > 0
    assert (img[:horizon_row - 3] == np.array(ground.SKY_RGB, np.uint8)).all()


def _painted_without_shortcut(scene, pos, R):
    """The plain painter's algorithm: ground, then per item (far to near) faces and textures."""
    c, Rm = np.asarray(pos, float), np.asarray(R, float)
    img = np.empty((INTR.height, INTR.width, 3), np.uint8)
    p = cam._Painter(img, c, Rm, INTR)
    ground.draw_ground(p, scene.seed)
    items = sorted(solids_of_scene(scene), key=lambda it: -float(np.linalg.norm(it.ref_w - c)))
    for it in items:
        p.item_faces(it)
        for args in it.textures:
            p.texture(*args)
    return img


@pytest.mark.parametrize("yaw", [0.0, 0.7, -1.0])
def test_frame_filling_card_skips_only_hidden_paint(yaw, monkeypatch):
    scene = Scene(target=Target("radial-symbol", 0.8, 0.1, 0.2),
                  obstacles=(Obstacle("circle", 1.5, 0.1, radius_m=0.1),), seed=3)
    R = look_rotation(yaw, -math.pi / 2, 0.0)
    covered = []
    real = cam._Painter.covers_frame

    def spy(self, *args):
        covered.append(real(self, *args))
        return covered[-1]

    monkeypatch.setattr(cam._Painter, "covers_frame", spy)
    # from close above the card (it fills the frame) up to where its rim enters the frame's
    # corners: the shortcut may only be taken while the result is the same
    for height_m in np.arange(0.12, 0.25, 0.005):
        pos = (0.8, 0.1, mk.OBJECT_TOP_Z_M + height_m)
        fast = render_clean(scene, pos, R, INTR)
        assert np.array_equal(fast, _painted_without_shortcut(scene, pos, R)), height_m
    assert covered[0] and not covered[-1]
    assert covered == sorted(covered, reverse=True)  # taken below some height, not above


def test_card_seen_obliquely_or_from_behind_does_not_claim_the_frame():
    scene = Scene(target=Target("radial-symbol", 0.0, 0.0, 0.0), seed=1)
    for pos, R in (((0.0, -0.3, 0.2), look_rotation(math.pi / 2, -0.4)),
                   ((0.03, 0.0, 0.05), look_rotation(0.0, math.pi / 2))):  # beside the post
        c = np.asarray(pos, float)
        p = cam._Painter(np.empty((INTR.height, INTR.width, 3), np.uint8), c, R, INTR)
        for it in solids_of_scene(scene):
            for args in it.textures:
                assert not p.covers_frame(*args, p.texture_plan(*args))
        assert np.array_equal(render_clean(scene, pos, R, INTR),
                              _painted_without_shortcut(scene, pos, R))
