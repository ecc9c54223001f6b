"""Arm FK against eq. (3) of 000, camera axes, and the grasp / lift / release rule."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host.task import REGISTRY
from mobigrasp.mcu_sim.world.actuators import JOINT_TABLE, pulse_for_angle
from mobigrasp.mcu_sim.world.arm import ARM_BY_METHOD, Arm, camera_point_platform
from mobigrasp.mcu_sim.world.scenario import loads_scenario
from mobigrasp.mcu_sim.world.world import World

G000 = ARM_BY_METHOD["000"]


def eq3_000(l1, l2, l3, t2, t3, t4, t5):
    """Eq. (3) of 000 written out independently (X_r right, Y_r forward, Z_r up)."""
    alpha = t2 + t3 + t4
    r = l1 * math.cos(t4) + l2 * math.cos(t4 + t3) + l3 * math.cos(alpha)
    return (r * math.sin(t5), r * math.cos(t5),
            l1 * math.sin(t4) + l2 * math.sin(t4 + t3) + l3 * math.sin(alpha))


def joint_strategy():
    return st.tuples(*[st.floats(JOINT_TABLE[ch].min_rad, JOINT_TABLE[ch].max_rad)
                       for ch in range(6)])


@examples(200)
@given(q=joint_strategy())
def test_fk_matches_eq3_of_000(q):
    got = camera_point_platform(G000, q)
    want = eq3_000(0.0955, 0.089, 0.097, q[2], q[3], q[4], q[5])
    assert got == pytest.approx(want, abs=1e-12)


def test_fk_known_postures():
    # all pitch joints at 0: arm stretched forward, l1 + l2 + l3 ahead of the waist
    assert camera_point_platform(G000, (0, 0, 0, 0, 0, 0)) == pytest.approx((0, 0.2815, 0))
    # waist +pi/2 turns the stretched arm to the right (+X_r)
    assert camera_point_platform(G000, (0, 0, 0, 0, 0, math.pi / 2)) == pytest.approx(
        (0.2815, 0, 0), abs=1e-12)
    # l1 straight up, l2 forward, l3 down
    q = (0, 0, -math.pi / 2, -math.pi / 2, math.pi / 2, 0)
    assert camera_point_platform(G000, q) == pytest.approx((0, 0.089, 0.0955 - 0.097))
    g001 = ARM_BY_METHOD["001"]
    assert camera_point_platform(g001, (0, 0, 0, 0, 0, 0)) == pytest.approx((0, 0.52, 0))


@examples(100)
@given(q=joint_strategy(), x=st.floats(-3, 3), y=st.floats(-3, 3), h=st.floats(-3.1, 3.1))
def test_camera_pose_in_the_world(q, x, y, h):
    arm = Arm(G000, initial=q)
    pos, r_wc = arm.camera_pose_world((x, y, h), 0)
    px, py, pz = eq3_000(0.0955, 0.089, 0.097, q[2], q[3], q[4], q[5])
    # the waist sits 0.10 m ahead of the axle, the shoulder 0.20 m above the ground
    fx, fy = math.cos(h), math.sin(h)
    rx, ry = math.sin(h), -math.cos(h)
    want = (x + (0.10 + py) * fx + px * rx, y + (0.10 + py) * fy + px * ry, 0.20 + pz)
    assert pos == pytest.approx(want, abs=1e-9)
    assert r_wc.T @ r_wc == pytest.approx(np.eye(3), abs=1e-9)
    assert np.linalg.det(r_wc) == pytest.approx(1.0, abs=1e-9)
    alpha = q[2] + q[3] + q[4]
    yaw = h - q[5]  # waist positive turns clockwise seen from above
    z_axis = (math.cos(alpha) * math.cos(yaw), math.cos(alpha) * math.sin(yaw), math.sin(alpha))
    assert r_wc[:, 2] == pytest.approx(z_axis, abs=1e-9)
    # roll 0 would put x horizontal to the right; roll theta1 turns x about z by theta1
    x0 = np.array([math.cos(yaw - math.pi / 2), math.sin(yaw - math.pi / 2), 0.0])
    y0 = np.cross(r_wc[:, 2], x0)
    assert math.atan2(r_wc[:, 0] @ y0, r_wc[:, 0] @ x0) == pytest.approx(q[1], abs=1e-9)


def test_home_camera_looks_down_with_forward_at_the_top_of_the_image():
    arm = Arm(G000)
    pos, r_wc = arm.camera_pose_world((1.0, 2.0, math.pi / 2), 0)
    assert pos == pytest.approx((1.0, 2.0 + 0.1 + 0.089, 0.2 + 0.0955 - 0.097))
    assert r_wc[:, 2] == pytest.approx((0, 0, -1), abs=1e-12)
    assert r_wc[:, 1] == pytest.approx((0, -1, 0), abs=1e-12)  # image down = backwards
    assert r_wc[:, 0] == pytest.approx((1, 0, 0), abs=1e-12)  # image right = robot's right


# ---- grasp ------------------------------------------------------------------------------

SCEN = """
[scenario]
name = "grasp"
method = "000"
seed = 2
time_limit_s = 30
[robot]
x_m = 0
y_m = 0
heading_rad = 0
[target]
kind = "{kind}"
x_m = {x}
y_m = {y}
heading_rad = {heading}
"""

# theta4 = 0.3, theta3 = -0.9126, alpha = -pi/2: fingertip at z = 0.08 m (the grasp point)
GRASP_Q = (0.0, 0.0, -math.pi / 2 + 0.9126 - 0.3, -0.9126, 0.3, 0.0)


def fingertip_x(q):
    return 0.10 + eq3_000(0.0955, 0.089, 0.097, q[2], q[3], q[4], q[5])[1]


def posed_world(dx=0.0, q=GRASP_Q):
    w = World(loads_scenario(SCEN.format(x=fingertip_x(q) + dx, y=0.0, kind="radial-symbol",
                                         heading=0), "grasp.toml",
                             methods=REGISTRY))
    for ch in range(1, 6):
        w.set_servo_pulse_us(ch, pulse_for_angle(ch, q[ch]))
    w.step_to(1_000_000)
    return w


def test_grasp_lift_carry_and_release():
    w = posed_world()
    tip = w.arm.fingertip_world(w.base.pose(), w.t_us)
    assert tip[2] == pytest.approx(0.08, abs=0.003)
    assert not w.gripper_grasped()
    w.set_servo_pulse_us(0, 2000)  # close
    w.step_to(1_500_000)
    assert w.gripper_grasped()
    assert w.truth()["collisions"]["target"] == 0
    w.set_servo_pulse_us(4, pulse_for_angle(4, 0.9))  # lift the shoulder
    w.step_to(2_500_000)
    t = w.truth()
    assert t["object"]["z_m"] > 0.04
    tip = w.arm.fingertip_world(w.base.pose(), w.t_us)
    assert t["object"]["x_m"] == pytest.approx(tip[0], abs=1e-6)
    # the base drives away with the object in hand
    w.set_wheel_duty(100, 100)
    w.step_to(4_500_000)
    w.set_wheel_duty(0, 0)
    w.step_to(5_500_000)
    t = w.truth()
    assert t["attached"] and t["object"]["x_m"] > 0.5
    # open: the object is put down under the gripper and is back in the plane
    w.set_servo_pulse_us(0, 1000)
    w.step_to(6_000_000)
    t = w.truth()
    assert not t["attached"] and t["object"]["z_m"] == 0.0
    assert w.target.in_space
    assert w.recorder.summary()["object_max_lift_m"] > 0.04


def test_a_dropped_object_the_base_drives_into_is_a_contact():
    w = posed_world()
    w.set_servo_pulse_us(0, 2000)  # close: held, out of the plane
    w.step_to(1_500_000)
    assert w.gripper_grasped()
    w.set_servo_pulse_us(0, 1000)  # open: put down ahead of the base
    w.step_to(2_000_000)
    assert not w.truth()["attached"] and w.target.in_space
    assert w.truth()["collisions"]["target"] == 0
    w.set_servo_pulse_us(4, pulse_for_angle(4, 0.9))  # the arm up, out of the way
    w.set_wheel_duty(100, 100)
    w.step_to(8_000_000)
    t = w.truth()
    assert t["collisions"]["target"] >= 1
    assert t["object"]["x_m"] > fingertip_x(GRASP_Q) + 0.1  # pushed ahead


@pytest.mark.parametrize("dx", [0.03, -0.025])
def test_no_grasp_when_the_fingertip_misses_the_grasp_point(dx):
    w = posed_world(dx=dx)
    w.set_servo_pulse_us(0, 2000)
    w.step_to(1_500_000)
    assert not w.gripper_grasped()
    assert w.truth()["object"]["z_m"] == 0.0


def test_no_grasp_with_the_wrong_gripper_pitch():
    # same fingertip height and reach, but alpha = -pi/2 + 0.5 (tilted)
    q = (0.0, 0.0, GRASP_Q[2] + 0.5, GRASP_Q[3], GRASP_Q[4], 0.0)
    w = posed_world(q=q)
    w.target.body.position = tuple(w.arm.fingertip_world(w.base.pose(), w.t_us)[:2])
    w.set_servo_pulse_us(0, 2000)
    w.step_to(1_500_000)
    assert not w.gripper_grasped()


def test_a_closed_gripper_arriving_at_the_object_does_not_grasp():
    w = World(loads_scenario(SCEN.format(x=fingertip_x(GRASP_Q), y=0.0, kind="radial-symbol",
                                         heading=0), "grasp.toml",
                             methods=REGISTRY))
    w.set_servo_pulse_us(0, 2000)  # closed while still at home
    w.step_to(500_000)
    for ch in range(1, 6):
        w.set_servo_pulse_us(ch, pulse_for_angle(ch, GRASP_Q[ch]))
    w.step_to(2_000_000)
    assert not w.gripper_grasped()


@pytest.mark.parametrize("method", ["000", "001", "002"])
def test_world_and_host_agree_on_the_mount_per_method(method):
    """docs/conventions.md (Base geometry): the world's shoulder height and waist offset are the
    host's task parameters, per method (002's arm sits low: 0.05 m)."""
    from mobigrasp.host.task import TaskParams

    geom, p = ARM_BY_METHOD[method], TaskParams.for_method(method)
    assert round(geom.h_shoulder_m * 1000) == p.h_shoulder_mm
    assert round(geom.mount_forward_m * 1000) == p.mount_forward_mm
    # 002's level grasp point is above its shoulder (theta2 <= 0 cannot reach below it)
    if method == "002":
        assert p.grasp_height_mm > p.h_shoulder_mm


def test_a_held_object_is_drawn_lifted_with_the_gripper_and_fills_its_camera():
    from mobigrasp.mcu_sim.world import markers as mk
    from mobigrasp.mcu_sim.world.camera import Intrinsics, render_clean
    from mobigrasp.mcu_sim.world.camera_scene import target_keypoints_w

    w = posed_world()
    intr = Intrinsics(f_px=611, u0_px=160, v0_px=120)
    pos, R = w.camera_pose_world()
    before = render_clean(w.camera_scene(), pos, R, intr)
    # the camera at the fingertip, at the grasp point: inside the standing object's post
    assert (before == np.array(mk.BODY_RGB, np.uint8)).all()
    w.set_servo_pulse_us(0, 2000)  # close
    w.step_to(1_500_000)
    w.set_servo_pulse_us(4, pulse_for_angle(4, 0.9))  # lift the shoulder
    w.step_to(2_500_000)
    assert w.gripper_grasped()
    tip = w.arm.fingertip_world(w.base.pose(), w.t_us)
    target = w.camera_scene().target
    assert target.z_m == pytest.approx(tip[2] - 0.08, abs=1e-9) and target.z_m > 0.04
    card = target_keypoints_w(target)["symbol_centre"]
    assert card[2] == pytest.approx(tip[2] + 0.02, abs=1e-3)  # the card 20 mm above the grip
    pos, R = w.camera_pose_world()
    held = render_clean(w.camera_scene(), pos, R, intr)
    assert (held == np.array(mk.BODY_RGB, np.uint8)).all()  # still inside: it moved along
    # the same pose with the object put back on the ground: the camera sees the floor
    ground = w.camera_scene()
    ground = type(ground)(target=type(target)(target.kind, target.x_m + 0.2, target.y_m,
                                              target.heading_rad), seed=ground.seed)
    assert not (render_clean(ground, pos, R, intr) == held).all()


def red_scen(x: float, y: float, heading: float) -> str:
    """A 002 scene: the red cylinder and its board at (x, y), facing ``heading``."""
    return SCEN.format(x=x, y=y, kind="red-cylinder", heading=heading).replace(
        'method = "000"', 'method = "002"')


def test_the_002_board_post_is_a_body_and_stays_when_the_cylinder_is_lifted():
    w = World(loads_scenario(red_scen(0.5, 0.3, math.pi), "post.toml", methods=REGISTRY))
    post = w.target.post
    assert post is not None and post.obstacle_index == -1
    # 0.17 m behind the cylinder (heading pi: behind is +x)
    assert tuple(post.body.position) == pytest.approx((0.67, 0.3), abs=1e-6)
    w.step_to(100_000)
    assert w.truth()["min_clearance_m"] == pytest.approx(
        math.hypot(0.67, 0.3) - 0.17 - 0.01 * math.sqrt(2), abs=0.02)
    w.target.detach_from_space()  # lifted by a gripper: the board stays on its post
    w.target.body.position = (0.2, -0.4)
    w.step_to(200_000)
    target = w.camera_scene().target
    assert target.board == pytest.approx((0.5, 0.3, math.pi), abs=1e-6)
    assert tuple(post.body.position) == pytest.approx((0.67, 0.3), abs=1e-6)


def test_the_base_driving_into_the_board_post_is_a_contact():
    w = World(loads_scenario(red_scen(0.6, 0.3, math.pi / 2), "post.toml",
                             methods=REGISTRY))
    assert tuple(w.target.post.body.position) == pytest.approx((0.6, 0.13), abs=1e-6)
    w.set_wheel_duty(200, 200)  # along y = 0: the post at y = 0.13 is in the footprint's way
    w.step_to(5_000_000)
    ep = [e for e in w.contacts.events if e.kind == "obstacle"]
    assert len(ep) == 1 and ep[0].index == -1
    assert w.base.pose()[1] < -0.03  # pushed aside by the post, not through it
    assert w.truth()["min_clearance_m"] < 0.001
