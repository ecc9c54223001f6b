"""The camera's shortcuts of perf round 4 give exactly what the general paths give.

- WorldPlant.capture skips apply_options (and seeding its generator) while the options change
  nothing: frames still equal camera.render; a frame handed out is the clean image, read-only,
  and keeps its pixels.
- _check_pose tells a proper rotation from a reflection and from a non-orthonormal matrix.
- The pose-free geometry of a placed texture (normal, corners) is kept per placement: it is the
  one computed from the arrays in hand, also for a moving target's new arrays.
- The arm's camera axes and platform transform, built from plain floats in one array call, are
  bit for bit the vector expressions they replace.
- World.camera_scene builds the obstacles in the renderer's types once: the same objects in
  every frame's scene, equal to the scenario's.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from camera_expect import expected_frame

from mobigrasp.cosim.rig_plant import WorldPlant
from mobigrasp.mcu_sim.world import camera as cam
from mobigrasp.mcu_sim.world.camera import CameraOptions, look_rotation
from mobigrasp.mcu_sim.world.camera_scene import Scene, Target, solids_of_scene
from mobigrasp.services.run_job import resolve_scenario


def test_plain_options_frames_equal_render_and_stay_what_they_were():
    _, scenario = resolve_scenario("paper000-exp1")
    plant = WorldPlant(scenario, 3)
    assert plant.options == CameraOptions()  # the shipped scenarios degrade nothing
    got = plant.capture(0)
    assert np.array_equal(got, expected_frame(plant, 0))
    keep = got.copy()
    with pytest.raises(ValueError):  # a frame handed out cannot be scribbled on
        got[:] = 0
    again = plant.capture(66_666)  # same pose: the clean image is reused
    assert np.array_equal(again, keep)
    # options set later take the general path again (noise differs per capture time), and
    # leave the clean image as it was
    for options in (CameraOptions(noise_std=3.0), CameraOptions(blur_px=3.0),
                    CameraOptions(brightness=1.5)):
        plant.options = options
        t_us = 133_333
        degraded = plant.capture(t_us)
        assert degraded.flags.writeable  # a new array, the caller's
        assert np.array_equal(degraded, expected_frame(plant, t_us))
        assert not np.array_equal(degraded, keep)
        assert np.array_equal(got, keep)
    plant.options = CameraOptions(brightness=1.0, blur_px=0.0, noise_std=0.0)
    assert np.array_equal(plant.capture(200_000), keep)
    # a new view is a new image: the frames handed out before keep their pixels
    plant.set_servo_pulse_us(5, 1700)  # turn the waist
    plant.step_to(400_000)
    moved = plant.capture(400_000)
    assert not np.array_equal(moved, keep) and np.array_equal(got, keep)


def test_check_pose_accepts_rotations_only():
    R = look_rotation(0.3, -0.8, 0.2)
    c, R2 = cam._check_pose((0.1, 0.2, 0.3), R)
    assert np.array_equal(R2, R) and c.tolist() == [0.1, 0.2, 0.3]
    for bad in (R * np.array([1.0, 1.0, -1.0]),  # a reflection: orthonormal, det -1
                R * 1.001,  # not orthonormal
                np.where(np.eye(3) > 0, np.nan, R)):
        with pytest.raises(ValueError):
            cam._check_pose((0.0, 0.0, 0.3), bad)
    for det in (1.0, -1.0):  # the sign the cofactor expansion gives is numpy's
        M = look_rotation(1.1, 0.4, -0.3) * np.array([1.0, 1.0, det])
        assert np.sign(np.linalg.det(M)) == det


def _geometry(tex, origin_w, ex_w, ey_w):
    h = tex.half_m
    normal = np.cross(ex_w, ey_w)
    corners = np.array([origin_w + sx * h * ex_w + sy * h * ey_w
                        for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    return normal, corners


def test_texture_geometry_is_that_of_the_arrays_in_hand():
    for heading in (0.0, 0.4, 0.4, -2.0):  # a moving target: new arrays every frame
        scene = Scene(target=Target("radial-symbol", 0.5, -0.2, heading), seed=1)
        (it,) = solids_of_scene(scene)
        for args in it.textures:
            for _ in range(2):  # computed, then kept
                normal, corners = cam._texture_geom(*args)
                want_n, want_c = _geometry(*args)
                assert np.allclose(normal, want_n, rtol=0, atol=1e-15)
                assert np.array_equal(corners, want_c)
    tex, origin, ex, ey = it.textures[0]
    ex2 = np.array([math.cos(1.0), math.sin(1.0), 0.0])
    ey2 = np.array([-math.sin(1.0), math.cos(1.0), 0.0])
    assert np.array_equal(cam._texture_geom(tex, origin, ex2, ey2)[1],
                          _geometry(tex, origin, ex2, ey2)[1])


def test_arm_camera_frames_in_plain_floats_equal_the_vector_expressions():
    from mobigrasp.mcu_sim.world import arm

    rng = np.random.default_rng(7)
    for _ in range(500):
        q = rng.uniform(-4.0, 4.0, 6).tolist()
        t1, t5 = q[1], q[5]
        alpha = q[2] + q[3] + q[4]
        ca, sa, c5, s5 = math.cos(alpha), math.sin(alpha), math.cos(t5), math.sin(t5)
        z = np.array([ca * s5, ca * c5, sa])
        x0, y0 = np.array([c5, -s5, 0.0]), np.array([sa * s5, sa * c5, -ca])
        x = math.cos(t1) * x0 + math.sin(t1) * y0
        y = math.cos(t1) * y0 - math.sin(t1) * x0
        axes = arm.camera_axes_platform(q)
        assert axes.tobytes() == np.column_stack([x, y, z]).tobytes()  # bit for bit
        bx, by, h = rng.uniform(-5.0, 5.0, 3).tolist()
        geom = arm.ARM_BY_METHOD["000"]
        fwd = np.array([math.cos(h), math.sin(h), 0.0])
        want = np.eye(4)
        want[:3, 0], want[:3, 1] = np.array([math.sin(h), -math.cos(h), 0.0]), fwd
        want[:3, 3] = [bx + geom.mount_forward_m * fwd[0], by + geom.mount_forward_m * fwd[1],
                       geom.h_shoulder_m]
        assert arm.platform_to_world(geom, (bx, by, h)).tobytes() == want.tobytes()


def test_camera_scene_obstacles_are_built_once_and_stay_the_scenarios():
    from mobigrasp.mcu_sim.world import camera_scene as cs
    from mobigrasp.mcu_sim.world.world import World

    _, scenario = resolve_scenario("paper001-sim2")
    world = World(scenario, 1)
    first = world.camera_scene()
    world.step_to(50_000)
    later = world.camera_scene()
    assert later.obstacles is first.obstacles  # built once: the obstacles never move
    assert len(first.obstacles) == len(scenario.obstacles) > 0
    for o, got in zip(scenario.obstacles, first.obstacles, strict=True):
        assert isinstance(got, cs.Obstacle)
        if o.shape == "circle":
            assert got == cs.Obstacle("circle", o.x_m, o.y_m, radius_m=o.radius_m,
                                      height_m=o.height_m)
        elif o.shape == "box":
            assert got == cs.Obstacle("box", o.x_m, o.y_m, width_m=o.width_m, depth_m=o.depth_m,
                                      heading_rad=o.heading_rad, height_m=o.height_m)


@pytest.mark.parametrize("name", ["paper000-exp1", "paper002-marker"])
def test_preload_changes_no_frame(name):
    _, scenario = resolve_scenario(name)
    cold, warm = WorldPlant(scenario, 1), WorldPlant(scenario, 1)
    warm.preload()
    assert warm._clean is not None and cold._clean is None
    for t_us in (0, 66_666):
        assert np.array_equal(cold.capture(t_us), warm.capture(t_us))
