"""host.transforms (eqs. (1)-(3) of 000) and host.ranging (002 §4, 000 pinhole ranges) against
float references and against the renderer's camera axes."""
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host import ranging, transforms
from mobigrasp.host.kinematics import PAPER_000

C = np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])


def rz(a):
    return np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])


def rx(a):
    return np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])


def fk_float(l1, l2, l3, t2, t3, t4, t5):
    a = t2 + t3 + t4
    r = l1 * math.cos(t4) + l2 * math.cos(t4 + t3) + l3 * math.cos(a)
    z = l1 * math.sin(t4) + l2 * math.sin(t4 + t3) + l3 * math.sin(a)
    return np.array([r * math.sin(t5), r * math.cos(t5), z])


@examples(100)
@given(st.integers(-1600, 600), st.integers(-1400, 1400))
def test_rotation_matches_float(alpha, theta5):
    ref = rz(-theta5 / 1000) @ rx(alpha / 1000) @ C
    got = np.array(transforms.r_c_r_q12(alpha, theta5)) / 4096
    assert np.max(np.abs(got - ref)) <= 4 / 4096


def test_signs_follow_conventions():
    geom = PAPER_000
    joints = (-500, -800, 1300, 0)  # alpha = 0: camera level, looking forward
    cr = transforms.camera_position_mm(geom, *joints)
    p = transforms.camera_to_platform_mm((0, 0, 1000), geom, *joints)
    assert p == (cr[0], cr[1] + 1000, cr[2])
    right = transforms.camera_to_platform_mm((100, 0, 1000), geom, *joints)
    assert right[0] - cr[0] == 100  # image right is platform right
    below = transforms.camera_to_platform_mm((0, 100, 1000), geom, *joints)
    assert below[2] - cr[2] == -100  # image down is platform down
    turned = transforms.camera_to_platform_mm((0, 0, 1000), geom, -500, -800, 1300, 500)
    assert turned[0] > 400  # theta5 > 0 looks to the right
    down = transforms.camera_to_platform_mm((0, 0, 300), geom, -500, -800, -271, 0)
    cr_down = transforms.camera_position_mm(geom, -500, -800, -271, 0)
    assert abs(down[2] - (cr_down[2] - 300)) <= 1 and abs(down[1] - cr_down[1]) <= 1


@examples(100)
@given(st.integers(-2800, 0), st.integers(-2700, 0), st.integers(0, 2900), st.integers(-1400, 1400),
       st.lists(st.integers(-800, 800), min_size=2, max_size=2), st.integers(50, 2000))
def test_camera_to_platform_against_float(t2, t3, t4, t5, xy, z):
    l1, l2, l3 = 95.5, 89.0, 97.0
    p_cv = (xy[0], xy[1], z)
    ref = rz(-t5 / 1000) @ rx((t2 + t3 + t4) / 1000) @ C @ np.array(p_cv, float)
    ref += fk_float(l1, l2, l3, t2 / 1000, t3 / 1000, t4 / 1000, t5 / 1000)
    got = np.array(transforms.camera_to_platform_mm(p_cv, PAPER_000, t2, t3, t4, t5))
    assert np.max(np.abs(got - ref)) <= 2.5  # Q12 entries over |p| <= 2300 mm + rounding


def test_matches_renderer_camera_axes():
    """A world point seen by a camera posed with the renderer's look_rotation lands where the
    platform frame says (platform heading = world +y, so X = world x, Y = world y)."""
    camera = pytest.importorskip("mobigrasp.mcu_sim.world.camera")
    rng = np.random.default_rng(4)
    for _ in range(20):
        theta5, alpha = rng.uniform(-1.2, 1.2), rng.uniform(-1.5, 0.5)
        heading = math.pi / 2
        R_wc = camera.look_rotation(heading - theta5, alpha)
        c = np.array([0.1, -0.2, 0.3])
        p = c + rng.uniform(-1, 1, 3) + np.array([0, 1.5, 0])
        p_cv_mm = tuple(int(round(v)) for v in 1000 * (R_wc.T @ (p - c)))
        got = np.array(transforms.r_c_r_q12(round(1000 * alpha), round(1000 * theta5))) @ \
            np.array(p_cv_mm) / 4096
        assert np.max(np.abs(got - 1000 * (p - c))) <= 3.0


def test_paper_camera_axes():
    assert transforms.paper_cam_to_cv(10, 500, 20) == (-10, -20, 500)


def test_bad_vector():
    with pytest.raises(ValueError):
        transforms.camera_to_platform_mm((1, 2), PAPER_000, 0, 0, 0, 0)


# --- ranging ----------------------------------------------------------------------------------
def test_range_from_size():
    assert ranging.range_from_size_mm(14_500, 350, 45 * 16) == 113  # T_d = 45 px of 002
    assert ranging.range_from_size_mm(109_000, 611, 100 * 16) == 666
    with pytest.raises(ValueError):
        ranging.range_from_size_mm(14_500, 350, 0)


@examples(100)
@given(st.integers(40, 1000), st.integers(0, 320 * 16), st.integers(0, 240 * 16),
       st.integers(-600, 600), st.integers(-800, 800))
def test_range_002_against_float(d_q4, u, v, alpha, t5):
    f, u0, v0 = 350, 160, 120
    d_oc = 14.5 * f / (d_q4 / 16)
    th_v = alpha / 1000 + math.atan((v0 - v / 16) / f)
    th_h = t5 / 1000 + math.atan((u / 16 - u0) / f)
    r = ranging.range_002(d_q4, u, v, alpha, t5)
    assert abs(r.d_oc_mm - d_oc) <= 0.5
    assert abs(r.theta_v_mrad - 1000 * th_v) <= 1.5 and abs(r.theta_h_mrad - 1000 * th_h) <= 1.5
    tol = 1.0 + 0.003 * d_oc
    assert abs(r.x_oc_mm - d_oc * math.cos(th_v) * math.sin(th_h)) <= tol
    assert abs(r.y_oc_mm - d_oc * math.cos(th_v) * math.cos(th_h)) <= tol
    assert abs(r.z_oc_mm - d_oc * math.sin(th_v)) <= tol


@examples(100)
@given(st.floats(0.12, 0.8), st.floats(-0.4, 0.4), st.floats(-0.15, 0.15), st.floats(-0.6, 0.4),
       st.floats(-0.8, 0.8))
def test_locate_ring_pair_exact_geometry(dist, lateral, height, alpha, t5):
    """Project the two rings' front points and the silhouette of a 25 mm cylinder with a float
    pinhole, feed the pixels in, get the axis point back (camera-centred, platform axes)."""
    f, u0, v0, R_cyl, D = 350.0, 160.0, 120.0, 0.025, 0.0145
    heading = 0.3
    yaw = heading - t5  # camera yaw (CCW) for a waist turned right by t5
    fwd = np.array([math.cos(heading), math.sin(heading), 0])
    right = np.array([math.sin(heading), -math.cos(heading), 0])
    axis = dist * fwd + lateral * right + np.array([0, 0, height])
    R_wc_fwd = np.array([math.cos(alpha) * math.cos(yaw), math.cos(alpha) * math.sin(yaw),
                         math.sin(alpha)])
    R_wc_right = np.array([math.sin(yaw), -math.cos(yaw), 0])
    R_wc = np.column_stack([R_wc_right, np.cross(R_wc_fwd, R_wc_right), R_wc_fwd])

    def proj(p):
        q = R_wc.T @ p
        return f * q[0] / q[2] + u0, f * q[1] / q[2] + v0, q[2]

    hdir = axis[:2] / np.linalg.norm(axis[:2])
    front = axis - R_cyl * np.array([hdir[0], hdir[1], 0])
    _, v_hi, z1 = proj(front + [0, 0, D / 2])
    u_mid, v_lo, z2 = proj(front - [0, 0, D / 2])
    side = R_cyl * np.array([-hdir[1], hdir[0], 0])
    u_a, _, _ = proj(axis + side)
    u_b, _, _ = proj(axis - side)
    u_c = (u_a + u_b) / 2
    if min(z1, z2) < 0.05 or not (0 <= u_a <= 319 and 0 <= u_b <= 319 and 0 <= v_hi <= 239
                                  and 0 <= v_lo <= 239):
        return  # only what the camera sees
    d_px = abs(v_lo - v_hi)
    v_mid = (v_lo + v_hi) / 2
    width = abs(u_a - u_b)
    fix = ranging.locate_ring_pair(round(16 * d_px), round(16 * u_c), round(16 * v_mid),
                                   round(16 * width), round(1000 * alpha), round(1000 * t5))
    true_mm = 1000 * np.array([axis @ right, axis @ fwd, axis[2]])
    true_dist = float(np.linalg.norm(true_mm))
    got = np.array([fix.x_mm, fix.y_mm, fix.z_mm])
    # Q4 pixel rounding of a 20-120 px spacing, and the silhouette's width is not exactly the
    # diameter at close range (tangent lines): a few percent of the distance
    assert np.max(np.abs(got - true_mm)) <= 0.04 * true_dist + 3
    assert abs(fix.dist_mm - true_dist) <= 0.03 * true_dist + 2
    # 12 mrad, plus the 2 mm by which the silhouette midpoint misses the axis projection at
    # the closest ranges (perspective of the tangent points; same cause as the +3 mm above)
    tol_mrad = 12 + 1000 * 2 / true_dist
    assert abs(fix.bearing_mrad - 1000 * math.atan2(true_mm[0], true_mm[1])) <= tol_mrad


@examples(100)
@given(st.integers(-300, 300), st.integers(0, 400), st.integers(-1200, 1200),
       st.integers(100, 3000))
def test_platform_bearing_parallax(cx, cy, bearing, dist):
    x = cx + dist * math.sin(bearing / 1000)
    y = cy + dist * math.cos(bearing / 1000)
    got = ranging.platform_bearing_mrad(cx, cy, bearing, dist)
    err = abs(got - 1000 * math.atan2(x, y))
    assert min(err, abs(err - 2000 * math.pi)) <= 3.0


def test_from_telemetry_pulses():
    from mobigrasp.host import arm_calib
    joints = (0, 0, -500, -800, 1300, 300)
    pulses = arm_calib.joints_to_pulses_us(joints)
    back = arm_calib.pulses_to_joints_mrad(pulses)
    got = transforms.camera_to_platform_from_servo_us((10, -20, 500), PAPER_000, pulses)
    assert got == transforms.camera_to_platform_mm((10, -20, 500), PAPER_000, *back[2:])
    with pytest.raises(ValueError):
        transforms.camera_to_platform_from_servo_us((0, 0, 1), PAPER_000, (1500,) * 5)
