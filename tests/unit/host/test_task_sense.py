"""host/task/sense.py: pinhole back-projection, detection adapters and frame changes vs float."""

import math

import detections as det
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host import kinematics
from mobigrasp.host.task import sense as ts

G = kinematics.PAPER_000
L = (95.5, 89.0, 97.0)


def cam_float(j):
    """Camera point and axes (x right, y down, z optical) in the platform frame, float."""
    t1, t2, t3, t4, t5 = (v / 1000 for v in j[1:6])
    a = t2 + t3 + t4
    r = L[0] * math.cos(t4) + L[1] * math.cos(t4 + t3) + L[2] * math.cos(a)
    zc = L[0] * math.sin(t4) + L[1] * math.sin(t4 + t3) + L[2] * math.sin(a)
    p = (r * math.sin(t5), r * math.cos(t5), zc)
    z = (math.cos(a) * math.sin(t5), math.cos(a) * math.cos(t5), math.sin(a))
    x0 = (math.cos(t5), -math.sin(t5), 0.0)
    y0 = (math.sin(a) * math.sin(t5), math.sin(a) * math.cos(t5), -math.cos(a))
    x = tuple(math.cos(t1) * u + math.sin(t1) * v for u, v in zip(x0, y0, strict=True))
    y = tuple(math.cos(t1) * v - math.sin(t1) * u for u, v in zip(x0, y0, strict=True))
    return p, x, y, z


@examples(60)
@given(t1=st.integers(-1571, 1571), t2=st.integers(-3000, 0), t3=st.integers(-2800, 0),
       t4=st.integers(0, 3000), t5=st.integers(-1400, 1400), u=st.integers(0, 319),
       v=st.integers(0, 239), depth=st.integers(100, 3000))
def test_back_projection_matches_float(t1, t2, t3, t4, t5, u, v, depth):
    j = (0, t1, t2, t3, t4, t5)
    p, x, y, z = cam_float(j)
    want = [p[i] + depth * z[i] + (u - 160) * depth / 611 * x[i] + (v - 120) * depth / 611 * y[i]
            for i in range(3)]
    got = ts.pixel_to_platform_mm_q4(G, j, ts.CAMERA_000, u * 16, v * 16, depth * 16)
    # Q12 axes: 2.5e-4 relative of ~3 m of lever -> about 1.5 mm at the far end
    assert math.dist([g / 16 for g in got], want) < 1.0 + depth * 6e-4


def test_axes_are_orthonormal_and_right_handed():
    x, y, z = ts.camera_axes_q12((0, 300, -2400, -200, 2300, 500))
    dot = [sum(a * b for a, b in zip(p, q, strict=True)) / 4096 ** 2
           for p, q in ((x, y), (y, z), (x, z))]
    assert all(abs(d) < 2e-3 for d in dot)
    cross = (x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0])
    assert all(abs(c / 4096 ** 2 - zz / 4096) < 2e-3 for c, zz in zip(cross, z, strict=True))


def test_camera_looking_straight_ahead_sees_the_object_ahead():
    # theta4 = 0, theta3 = 0, theta2 = 0: camera 281.5 mm ahead at shoulder height, alpha = 0
    j = (0, 0, 0, 0, 0, 0)
    p = ts.object_in_platform("radial_symbol", det.radial(2560, 1920, 1000),
                              G, j, ts.CAMERA_000)
    assert [round(v / 16) for v in p] == [0, 1282, 0]
    # right of the image centre -> +X_r (right); above -> +Z_r
    p = ts.object_in_platform("radial_symbol", det.radial(16 * 221, 16 * 59, 1000),
                              G, j, ts.CAMERA_000)
    assert round(p[0] / 16) == 100 and round(p[2] / 16) == 100


def test_depth_from_sizes_of_the_papers():
    j = (0, 0, 0, 0, 0, 0)
    # radial symbol: the depth is its Y_oc (L f / d, computed by the detector)
    p = ts.object_in_platform("radial_symbol", det.radial(2560, 1920, 1000), G, j,
                              ts.CAMERA_000)
    assert abs(p[1] / 16 - 1281.5) < 2
    # dual "+": the depth is D_is (corrected for foreshortening by the detector), at the
    # midpoint of the two "+"
    p = ts.object_in_platform("dual_plus", det.dual_plus(2400, 1920, 2720, 1920, 500),
                              G, j, ts.CAMERA_000)
    assert abs(p[1] / 16 - 781.5) < 2 and abs(p[0]) < 16
    # red cylinder (002): D_OC = 14.5 * 350 / d_pixel; 45 px -> 112.8 mm
    p = ts.object_in_platform("red_cylinder", det.red_cylinder(2560, 1920, 45 * 16),
                              kinematics.PAPER_002, j, ts.CAMERA_002)
    assert abs(p[1] / 16 - (281.5 + 112.8)) < 1.5
    assert ts.d_pixel_px(det.red_cylinder(0, 0, 45 * 16 + 7)) == 45
    # double cross (002 board): crosses 130 mm apart seen 91 px apart at f = 350: the board
    # 500 mm along the axis, the cylinder 150 mm in front of it
    p = ts.object_in_platform("double_cross", det.double_cross(2560, 1920, 91 * 16),
                              kinematics.PAPER_002, j, ts.CAMERA_002)
    assert abs(p[1] / 16 - (281.5 + 130 * 350 / 91 - 150)) < 1.5
    assert ts.d_pixel_px(det.double_cross(0, 0, 91 * 16)) == 91
    assert ts.object_in_platform("dual_plus", det.dual_plus(1, 1, 1, 1, 0),
                                 G, j, ts.CAMERA_000) is None  # no depth
    assert ts.object_in_platform("red_cylinder", det.red_cylinder(1, 1, 0),
                                 kinematics.PAPER_002, j, ts.CAMERA_002) is None
    with pytest.raises(ValueError, match="detector"):
        ts.object_in_platform("spoke", det.spoke(0, 16), G, j, ts.CAMERA_000)
    # a result of another detector, or an untyped bag of fields, is refused by type
    for wrong in (det.red_cylinder(2560, 1920, 45 * 16), {"u_q4": 2560, "v_q4": 1920,
                                                         "y_oc_mm": 1000}):
        with pytest.raises(TypeError, match="radial_symbol"):
            ts.object_in_platform("radial_symbol", wrong, G, j, ts.CAMERA_000)


def test_bearing_of_002():
    # marker 50 px right of centre with f = 350 and the waist at -100 mrad
    e = ts.bearing_mrad(det.double_cross(16 * 210, 0), -100, ts.CAMERA_002)
    assert abs(e - (-100 + 1000 * math.atan(50 / 350))) <= 1


def test_spoke_reading():
    assert ts.spoke_reading(det.spoke(120, 30 * 16)) == (120, 30)
    assert ts.spoke_reading(det.spoke(-785, 30 * 16 + 8)) == (-785, 31)  # width rounded
    assert ts.spoke_reading(None) is None
    with pytest.raises(TypeError):
        ts.spoke_reading({"angle_mrad": 120, "w_px": 30})


@examples(60)
@given(x=st.integers(-5000, 5000), y=st.integers(-5000, 5000), h=st.integers(-3141, 3141),
       px=st.integers(-3000, 3000), py=st.integers(-3000, 3000))
def test_platform_odometry_round_trip(x, y, h, px, py):
    ox, oy = ts.platform_to_odom_mm(x, y, h, 100, (px * 16, py * 16, 0))
    # float reference: waist 100 mm ahead of the axle, X_r right, Y_r forward
    fx, fy = math.cos(h / 1000), math.sin(h / 1000)
    wx = x + (100 + py) * fx + px * fy
    wy = y + (100 + py) * fy - px * fx
    assert abs(ox - wx) <= 2 and abs(oy - wy) <= 2
    bx, by = ts.odom_to_platform_q4(x, y, h, 100, ox, oy)
    assert abs(bx / 16 - px) <= 3 and abs(by / 16 - py) <= 3
