"""The two "+" of a dual "+" sighting placed where their pixel rays meet the object's top
(host/task/sense.py plus_positions with ``top_q4``): a pair seen obliquely along the view keeps
its 47.3 mm; at one depth for both it comes out shortened."""

import math

import detections as det
import pytest

from mobigrasp.host.kinematics import ArmGeometry, fk_mm_q4
from mobigrasp.host.task.sense import CAMERA_000, camera_axes_q12, plus_positions

GEOM_001 = ArmGeometry.from_mm(160.0, 160.0, 200.0)
TOP_Z_MM = 100 - 108  # object top 100 mm, 001 shoulder 108 mm: platform z of the top


def _project(joints, p_mm):
    pc = [v / 16 for v in fk_mm_q4(GEOM_001, *joints[2:6])]
    x, y, z = ([a / 4096 for a in ax] for ax in camera_axes_q12(joints))
    d = [p_mm[i] - pc[i] for i in range(3)]
    zc = sum(d[i] * z[i] for i in range(3))
    u = 160 + 611 * sum(d[i] * x[i] for i in range(3)) / zc
    v = 120 + 611 * sum(d[i] * y[i] for i in range(3)) / zc
    return round(u * 16), round(v * 16), zc


@pytest.mark.parametrize("pair_rad", [0.0, 0.7, 1.571])
def test_the_pair_keeps_its_spacing_seen_along_the_view(pair_rad):
    joints = (0, 0, -1200, -1001, 1571, 0)  # 001's close-look posture of ADJUST
    centre = (0.0, 330.0, TOP_Z_MM)  # platform frame: ahead of the waist, on the top
    ends = [(centre[0] + k * 23.65 * math.sin(pair_rad),
             centre[1] + k * 23.65 * math.cos(pair_rad), TOP_Z_MM) for k in (-1, 1)]
    (u1, v1, z1), (u2, v2, z2) = (_project(joints, e) for e in ends)
    _, _, zc = _project(joints, centre)
    d = det.dual_plus(u1, v1, u2, v2, round(zc), d_pixel_q4=16 * 100)
    on_top = plus_positions(d, GEOM_001, joints, CAMERA_000, TOP_Z_MM * 16)
    for got, want in zip(on_top, ends, strict=True):
        assert all(abs(g / 16 - w) <= 2.0 for g, w in zip(got, want, strict=True)), (got, want)
    one_depth = plus_positions(d, GEOM_001, joints, CAMERA_000)
    (ax, ay, _), (bx, by, _) = one_depth
    apart = math.hypot(ax - bx, ay - by) / 16
    if pair_rad == 0.0:  # along the view: shortened at one depth
        assert apart < 40


def test_a_ray_that_does_not_reach_the_top_gives_no_pair():
    joints = (0, 0, 300, -1001, 1571, 0)  # looking up
    d = det.dual_plus(150 * 16, 100 * 16, 170 * 16, 100 * 16, 300)
    assert plus_positions(d, GEOM_001, joints, CAMERA_000, TOP_Z_MM * 16) is None
