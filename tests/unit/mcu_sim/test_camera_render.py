"""The eye-in-hand camera renderer: geometry, determinism, occlusion, clipping and options."""

import math

import numpy as np
import pytest

from mobigrasp.mcu_sim.world import markers as mk
from mobigrasp.mcu_sim.world.camera import (
    CameraOptions,
    Intrinsics,
    look_rotation,
    project,
    render,
    render_frame,
)
from mobigrasp.mcu_sim.world.camera_scene import (
    Clutter,
    Obstacle,
    Scene,
    Target,
    target_keypoints_w,
)

INTR = Intrinsics()
BLUE = (20, 40, 230)


def _blue_mask(img):
    r, g, b = (img[..., k].astype(int) for k in range(3))
    return (b > 150) & (r < 90) & (g < 110)


def _centroid(mask):
    v, u = np.nonzero(mask)
    return np.array([u.mean(), v.mean()])


@pytest.mark.parametrize("pose", [
    ((0.0, 0.0, 0.35), (0.0, -0.35, 0.0)),
    ((0.2, -0.1, 0.50), (0.3, -0.6, 0.2)),
    ((0.78, 0.02, 0.30), (0.1, -1.2, -0.4)),
])
def test_projected_point_lands_on_rendered_pixel(pose):
    pos, (yaw, pitch, roll) = pose
    disc = Clutter("disc", 0.9, 0.05, 0.02, BLUE)
    scene = Scene(None, clutter=(disc,), seed=1)
    R = look_rotation(yaw, pitch, roll)
    img = render(scene, pos, R, INTR)
    uv = project(np.array([[0.9, 0.05, 0.0005]]), pos, R, INTR)[0]
    # a small circle's image centroid is within a fraction of a pixel of its centre's image
    assert np.all(np.abs(_centroid(_blue_mask(img)) - uv) < 1.0)


def test_plus_centre_projects_into_the_dark_plus():
    t = Target("radial-symbol", 1.0, 0.0, 0.0)
    kp = target_keypoints_w(t)
    pos = np.array([1.0, 0.0, 0.27])
    R = look_rotation(0.0, -math.pi / 2, 0.0)
    img = render(Scene(t), pos, R, INTR)
    grey = img.mean(axis=2)
    for name in ("plus_1", "plus_2"):
        u, v = project(kp[name][None], pos, R, INTR)[0]
        ui, vi = int(round(u)), int(round(v))
        assert grey[vi, ui] < 60  # centre of the "+" is dark
        # the dark "+" is symmetric about the projected centre to within 1 px along image x
        row = grey[vi] < 128
        left = ui - np.argmin(row[ui::-1])
        right = ui + np.argmin(row[ui:])
        assert abs((left + right - 1) / 2 - u) <= 1.0
    centre = project(kp["symbol_centre"][None], pos, R, INTR)[0]
    assert grey[int(round(centre[1])), int(round(centre[0]))] > 180  # white between the "+"


def test_same_seed_gives_identical_frames_and_noise_is_seeded():
    scene = Scene(Target("red-cylinder", 0.8, 0.1, math.pi), seed=7)
    R = look_rotation(0.0, -0.2)
    opt = CameraOptions(noise_std=8.0, blur_px=2.0, brightness=1.2)
    a = render(scene, (0.0, 0.0, 0.3), R, INTR, opt, np.random.default_rng(5))
    b = render(scene, (0.0, 0.0, 0.3), R, INTR, opt, np.random.default_rng(5))
    c = render(scene, (0.0, 0.0, 0.3), R, INTR, opt, np.random.default_rng(6))
    assert a.dtype == np.uint8 and a.shape == (240, 320, 3)
    assert a.tobytes() == b.tobytes()
    assert a.tobytes() != c.tobytes()
    f1 = render_frame(3, 12_345, scene, (0.0, 0.0, 0.3), R, INTR, opt)
    f2 = render_frame(3, 12_345, scene, (0.0, 0.0, 0.3), R, INTR, opt)
    assert (f1.seq, f1.capture_us) == (3, 12_345) and f1.rgb.tobytes() == f2.rgb.tobytes()


def test_ground_texture_is_fixed_per_scene_seed():
    R = look_rotation(0.0, -0.5)
    a = render(Scene(seed=1), (0, 0, 0.4), R)
    b = render(Scene(seed=2), (0, 0, 0.4), R)
    assert a.tobytes() != b.tobytes()
    assert a[200].std() > 1.0  # textured, not flat


def test_obstacle_in_front_hides_the_marker():
    t = Target("radial-symbol", 1.2, 0.0, 0.0)
    pos, R = (0.0, 0.0, 0.35), look_rotation(0.0, -0.2)
    centre = project(target_keypoints_w(t)["symbol_centre"][None], pos, R, INTR)[0]
    u, v = int(round(centre[0])), int(round(centre[1]))
    seen = render(Scene(t), pos, R)
    wall = Obstacle("box", 0.6, 0.0, width_m=0.05, depth_m=0.4, height_m=0.6, rgb=(200, 160, 0))
    hidden = render(Scene(t, obstacles=(wall,)), pos, R)
    assert seen[v, u].mean() > 180  # white card centre visible
    r, g, b = hidden[v, u].astype(int)
    assert r > 100 and r > g > b and b < 40  # the obstacle's (shaded) colour
    # the obstacle behind the target does not hide it
    behind = Obstacle("box", 2.0, 0.0, width_m=0.05, depth_m=0.4, height_m=0.6, rgb=(200, 160, 0))
    assert render(Scene(t, obstacles=(behind,)), pos, R)[v, u].mean() > 180


def test_nothing_behind_the_camera_is_drawn():
    pos, R = (0.0, 0.0, 0.3), look_rotation(0.0, -0.1)
    base = render(Scene(seed=4), pos, R)
    back = Obstacle("box", -0.6, 0.0, width_m=0.3, depth_m=2.0, height_m=1.0, rgb=(255, 0, 0))
    assert render(Scene(obstacles=(back,), seed=4), pos, R).tobytes() == base.tobytes()
    # an obstacle that straddles the camera plane is clipped, not mirrored: red only below
    # the horizon line of its near face, nothing in the upper image half beyond its extent
    side = Obstacle("box", 0.0, -0.3, width_m=2.0, depth_m=0.1, height_m=0.2, rgb=(255, 0, 0))
    img = render(Scene(obstacles=(side,), seed=4), pos, R)
    red = (img[..., 0] > 200) & (img[..., 1] < 60)
    assert red.any()
    assert not red[:, :160].any()  # the box is on the right (y < 0) of a camera facing +x


def test_options_change_the_image_as_stated():
    scene = Scene(Target("radial-symbol", 0.9, 0.0, 0.0), seed=2)
    pos, R = (0.0, 0.0, 0.4), look_rotation(0.0, -0.35)
    clean = render(scene, pos, R).astype(float)
    bright = render(scene, pos, R, options=CameraOptions(brightness=0.7)).astype(float)
    assert abs(bright.mean() / clean.mean() - 0.7) < 0.01
    noisy = render(scene, pos, R, options=CameraOptions(noise_std=8.0),
                   rng=np.random.default_rng(0)).astype(float)
    d = (noisy - clean)[clean.min(axis=2) > 20]  # away from clipping at 0
    assert abs(d.mean()) < 0.3 and abs(d.std() - 8.0) < 0.4
    pos, R = (0.9, 0.0, 0.30), look_rotation(0.0, -math.pi / 2)  # symbol seen from above
    clean = render(scene, pos, R).astype(float)
    blur = render(scene, pos, R, options=CameraOptions(blur_px=6.0)).astype(float)
    gx = lambda im: (np.diff(im, axis=1) ** 2).mean()  # noqa: E731
    gy = lambda im: (np.diff(im, axis=0) ** 2).mean()  # noqa: E731
    hx, hy = gx(blur) / gx(clean), gy(blur) / gy(clean)
    assert hx < 0.4 and hx < 0.6 * hy  # streaks along x take gradient energy mostly along x
    vert = render(scene, pos, R, options=CameraOptions(blur_px=6.0, blur_angle_rad=math.pi / 2))
    vx, vy = gx(vert.astype(float)) / gx(clean), gy(vert.astype(float)) / gy(clean)
    assert vy < 0.4 and vy < 0.6 * vx


def test_double_cross_board_stands_behind_the_red_cylinder():
    t = Target("red-cylinder", 1.0, 0.0, math.pi)  # faces a robot at the origin
    kp = target_keypoints_w(t)
    assert kp["board_centre"][0] == pytest.approx(1.0 + mk.BOARD_BEHIND_M)
    assert np.linalg.norm(kp["ring_hi"] - kp["ring_lo"]) == pytest.approx(mk.RING_SPACING_M)
    assert np.linalg.norm(kp["cross_1"] - kp["cross_2"]) == pytest.approx(mk.CROSS_SPACING_M)
    pos, R = (0.0, 0.0, 0.25), look_rotation(0.0, -0.05)
    intr = Intrinsics(f_px=350.0)
    img = render(Scene(t), pos, R, intr)
    uv = project(np.array([kp["cross_1"], kp["cross_2"], kp["cylinder_centre"]]), pos, R, intr)
    assert uv[0, 0] < uv[1, 0]  # cross_1 is the left one seen from the front
    for u, v in uv[:2]:
        assert img[int(round(v)), int(round(u))].mean() < 60  # dark cross centres
    u, v = uv[2]
    r, g, b = img[int(round(v)) + 3, int(round(u))].astype(int)
    assert r > 120 and g < 60 and b < 60  # red cylinder between the rings


@pytest.mark.parametrize("bad", [
    lambda: render(Scene(), (0, 0, 1), np.eye(2)),
    lambda: render(Scene(), (0, 0), np.eye(3)),
    lambda: render(Scene(), (0, 0, 1), np.diag([1.0, 1.0, -1.0])),
    lambda: render("scene", (0, 0, 1), np.eye(3)),
    lambda: project(np.zeros((3, 2)), (0, 0, 1), np.eye(3), INTR),
    lambda: CameraOptions(noise_std=-1.0),
    lambda: CameraOptions(brightness=0.0),
    lambda: CameraOptions(blur_px=float("nan")),
    lambda: Intrinsics(f_px=0.0),
    lambda: Intrinsics(width=320.5),
    lambda: Target("square", 0.0, 0.0),
    lambda: Target("radial-symbol", float("inf"), 0.0),
    lambda: Obstacle("circle", 0.0, 0.0),
    lambda: Obstacle("box", 0.0, 0.0, width_m=0.1),
    lambda: Clutter("disc", 0.0, 0.0, 0.1, (300, 0, 0)),
    lambda: Scene(obstacles=[Obstacle("circle", 0.0, 0.0, radius_m=0.1)]),
])
def test_bad_input_is_a_value_error(bad):
    with pytest.raises(ValueError):
        bad()


def test_project_returns_nan_behind_the_camera():
    R = look_rotation(0.0, 0.0)
    uv = project(np.array([[1.0, 0.0, 0.3], [-1.0, 0.0, 0.3]]), (0, 0, 0.3), R, INTR)
    assert uv[0] == pytest.approx([160.0, 120.0])
    assert np.isnan(uv[1]).all()


def test_view_samplers_are_seeded_and_see_their_target():
    from mobigrasp.mcu_sim.world import camera_views as views

    for sampler in (views.radial_far, views.dual_plus, views.spoke, views.empty):
        a, b = sampler(np.random.default_rng(3)), sampler(np.random.default_rng(3))
        assert a.scene == b.scene and np.array_equal(a.cam_pos_w, b.cam_pos_w)
        if sampler is views.empty:
            assert a.scene.target is None
            continue
        kp = target_keypoints_w(a.scene.target)
        uv = project(kp["symbol_centre"][None], a.cam_pos_w, a.R_wc, a.intr)[0]
        if sampler is views.spoke:  # straight over one "+", the symbol centre is out of view
            uv = a.truth["centre_uv"]
        assert 0 <= uv[0] < 320 and 0 <= uv[1] < 240
        # truth depth is the symbol centre's depth along the optical axis
        if "y_oc_mm" in a.truth:
            depth = (a.R_wc.T @ (kp["symbol_centre"] - a.cam_pos_w))[2] * 1000
            assert a.truth["y_oc_mm"] == pytest.approx(depth)
