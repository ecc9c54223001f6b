"""What the task learns from a detection: object position in the platform and odometry frames.

Each detector returns its own typed result (host/vision/registry.py names the type) and says in
its module how the result becomes a target: ``sighting(result, f_px)`` gives the pixel (Q4 px)
and the depth along the optical axis (Q4 mm). The camera model is the pinhole of 000 §III.A /
002 §4 with the frames of docs/conventions.md: the camera sits at the eq. (3) point of 000, its
optical axis z along l3 (yaw theta5, pitch alpha), x right and y down (OpenCV) turned by the
wrist roll theta1. A pixel (u, v) at depth Y along the axis is

    P = P_cr + Y z + (u - u0) Y / f x + (v - v0) Y / f y,

which is eqs. (1)-(2) of 000 with the paper's X_oc = (u0 - u) Y / f (X_c to the left) and
Z_oc = (v0 - v) Y / f (Z_c up) written in OpenCV axes.  Depths: radial symbol Y = L f / d
(L = 109 mm, 000 §III.A), dual "+" D_is = D_act f / d_pixel (D_act = 47.3 mm), red cylinder
D_OC = D f / d_pixel (D = 14.5 mm, 002 §4); the distances D_is and D_OC are used as depths, as the
papers do (002's task places the red cylinder by host.ranging.locate_ring_pair instead, through
``Method.object_position``).  Integer only: Q12 axes, Q4 mm positions, Q4 px pixel coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from mobigrasp.host.fixedpoint import atan2_mrad, cos_q12, sin_q12
from mobigrasp.host.kinematics import ArmGeometry, fk_mm_q4
from mobigrasp.host.vision import double_cross, registry

# 002's guidance board (docs/markers.md): cross centres this far apart (host/vision/double_cross)
CROSS_SPACING_MM_Q4 = double_cross.CROSS_SPACING_MM_Q4


@dataclass(frozen=True)
class CameraModel:
    """Pinhole intrinsics in px: 000 f = 611, 002 f = 350, (u0, v0) = (160, 120)."""

    f_px: int = 611
    u0_px: int = 160
    v0_px: int = 120


CAMERA_000 = CameraModel(611, 160, 120)
CAMERA_002 = CameraModel(350, 160, 120)


def _r12(v: int) -> int:
    return (v + 2048) >> 12


def camera_axes_q12(joints_mrad: tuple[int, ...]) -> tuple[tuple[int, int, int], ...]:
    """Camera x (right), y (down), z (optical axis) in the platform frame, Q12 (conventions)."""
    t1, t5 = joints_mrad[1], joints_mrad[5]
    alpha = joints_mrad[2] + joints_mrad[3] + joints_mrad[4]
    ca, sa, c5, s5 = cos_q12(alpha), sin_q12(alpha), cos_q12(t5), sin_q12(t5)
    z = (_r12(ca * s5), _r12(ca * c5), sa)
    x0 = (c5, -s5, 0)
    y0 = (_r12(sa * s5), _r12(sa * c5), -ca)  # z cross x0
    c1, s1 = cos_q12(t1), sin_q12(t1)
    x = tuple(_r12(c1 * a + s1 * b) for a, b in zip(x0, y0, strict=True))
    y = tuple(_r12(c1 * b - s1 * a) for a, b in zip(x0, y0, strict=True))
    return x, y, z


def pixel_to_platform_mm_q4(geom: ArmGeometry, joints_mrad: tuple[int, ...], cam: CameraModel,
                            u_q4: int, v_q4: int, depth_mm_q4: int) -> tuple[int, int, int]:
    """The point seen at pixel (u, v) (Q4 px) at depth Y (Q4 mm) in the platform frame, Q4 mm."""
    pc = fk_mm_q4(geom, joints_mrad[2], joints_mrad[3], joints_mrad[4], joints_mrad[5])
    x, y, z = camera_axes_q12(joints_mrad)
    f_q4 = cam.f_px * 16
    off_x = depth_mm_q4 * (u_q4 - cam.u0_px * 16) // f_q4  # Q4 mm along camera x
    off_y = depth_mm_q4 * (v_q4 - cam.v0_px * 16) // f_q4
    return tuple(pc[i] + _r12(depth_mm_q4 * z[i] + off_x * x[i] + off_y * y[i]) for i in range(3))


def object_in_platform(name: str, det: Any, geom: ArmGeometry, joints_mrad: tuple[int, ...],
                       cam: CameraModel) -> tuple[int, int, int] | None:
    """Object (marker centre) position in the platform frame, Q4 mm; None if not usable.

    A result of another type than detector ``name`` returns raises TypeError; a detector
    whose result gives no target (no ``sighting`` in its row) raises ValueError."""
    if det is None:
        return None
    row = registry.row(name)
    to_target = row.sighting_fn()
    if to_target is None:
        raise ValueError(f"no object position from detector {name!r}")
    seen = to_target(registry.check(name, det), cam.f_px)
    if seen is None or seen[2] <= 0:
        return None
    return pixel_to_platform_mm_q4(geom, joints_mrad, cam, *seen)


def plus_positions(det: Any, geom: ArmGeometry, joints_mrad: tuple[int, ...],
                   cam: CameraModel, top_q4: int | None = None
                   ) -> tuple[tuple[int, int, int], ...] | None:
    """Both "+" centres of a dual "+" detection in the platform frame (Q4 mm), at its depth;
    with ``top_q4`` (the object top's platform z, Q4 mm) each where its pixel ray meets that
    plane instead (a pair seen obliquely along the view is not shortened to one depth)."""
    det = registry.check("dual_plus", det)
    if object_in_platform("dual_plus", det, geom, joints_mrad, cam) is None:
        return None
    depth = det.dist_mm * 16
    pts = (pixel_to_platform_mm_q4(geom, joints_mrad, cam, det.u1_q4, det.v1_q4, depth),
           pixel_to_platform_mm_q4(geom, joints_mrad, cam, det.u2_q4, det.v2_q4, depth))
    if top_q4 is None:
        return pts
    out = []
    for (u, v), p in zip(((det.u1_q4, det.v1_q4), (det.u2_q4, det.v2_q4)), pts, strict=True):
        far = pixel_to_platform_mm_q4(geom, joints_mrad, cam, u, v, 2 * depth)
        dz = far[2] - p[2]  # z along the ray per ``depth``: linear in the depth
        if dz >= 0:
            return None  # the ray does not go down to the top
        d = depth + (top_q4 - p[2]) * depth // dz
        if not 0 < d <= 4 * depth:
            return None
        out.append(pixel_to_platform_mm_q4(geom, joints_mrad, cam, u, v, d))
    return tuple(out)


def bearing_mrad(det: Any, theta5_mrad: int, cam: CameraModel) -> int | None:
    """002's e: bearing of the double cross's midpoint from the platform heading, right
    positive.

    Computed from the pixel column and the waist yaw (the image is not turned by the pitch for
    a level roll), so it does not depend on the yaw the detector was given."""
    um = registry.check("double_cross", det).um_q4
    return theta5_mrad + atan2_mrad(um - cam.u0_px * 16, cam.f_px * 16)


# --- platform frame <-> odometry frame -------------------------------------------------------
def platform_to_odom_mm(x_mm: int, y_mm: int, heading_mrad: int, mount_forward_mm: int,
                        p_q4: tuple[int, int, int]) -> tuple[int, int]:
    """Odometry-frame (x, y) mm of a platform-frame point (Y_r forward, X_r right)."""
    c, s = cos_q12(heading_mrad), sin_q12(heading_mrad)
    fwd_q4 = p_q4[1] + mount_forward_mm * 16
    right_q4 = p_q4[0]
    # forward = (c, s), right = (s, -c)
    dx = _r12(fwd_q4 * c + right_q4 * s)
    dy = _r12(fwd_q4 * s - right_q4 * c)
    return x_mm + (dx + 8) // 16, y_mm + (dy + 8) // 16


def odom_to_platform_q4(x_mm: int, y_mm: int, heading_mrad: int, mount_forward_mm: int,
                        obj_x_mm: int, obj_y_mm: int) -> tuple[int, int]:
    """Platform-frame (X_r, Y_r) in Q4 mm of an odometry-frame point."""
    c, s = cos_q12(heading_mrad), sin_q12(heading_mrad)
    dx, dy = (obj_x_mm - x_mm) * 16, (obj_y_mm - y_mm) * 16
    fwd = _r12(dx * c + dy * s) - mount_forward_mm * 16
    right = _r12(dx * s - dy * c)
    return right, fwd


def spoke_reading(det: Any) -> tuple[int, int] | None:
    """(spoke image angle mrad = atan k_T, width w_T px) from a spoke detection (000 §III.A)."""
    if det is None:
        return None
    det = registry.check("spoke", det)
    return det.angle_mrad, (det.width_q4 + 8) // 16


def d_pixel_px(det: Any) -> int | None:
    """Ring spacing d_pixel of the red cylinder (002 §2.2), or the spacing of the double
    cross's two crosses, in whole px."""
    if det is None:
        return None
    if not isinstance(det, registry.row("red_cylinder").result_type()):
        det = registry.check("double_cross", det)
    return (det.d_pixel_q4 + 8) // 16
