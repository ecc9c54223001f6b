"""What the task learns from a detection: object position in the platform and odometry frames.

Detector results (host/vision, helpers D1/D2) are read through :func:`field` by the names of
their briefs (``u_q4``, ``v_q4``, ``d_pixel_q4`` ..., dataclass attributes or dict keys), so a
renamed field needs one change here.  The camera model is the pinhole of 000 §III.A / 002 §4 with
the frames of docs/conventions.md: the camera sits at the eq. (3) point of 000, its optical axis
z along l3 (yaw theta5, pitch alpha), x right and y down (OpenCV) turned by the wrist roll theta1.
A pixel (u, v) at depth Y along the axis is

    P = P_cr + Y z + (u - u0) Y / f x + (v - v0) Y / f y,

which is eqs. (1)-(2) of 000 with the paper's X_oc = (u0 - u) Y / f (X_c to the left) and
Z_oc = (v0 - v) Y / f (Z_c up) written in OpenCV axes.  Depths: radial symbol Y = L f / d
(L = 109 mm, 000 §III.A), dual "+" D_is = D_act f / d_pixel (D_act = 47.3 mm), red cylinder
D_OC = D f / d_pixel (D = 14.5 mm, 002 §4); the distances D_is and D_OC are used as depths, as the
papers do.  Integer only: Q12 axes, Q4 mm positions, Q4 px pixel coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from mobigrasp.host.fixedpoint import atan2_mrad, cos_q12, sin_q12
from mobigrasp.host.kinematics import ArmGeometry, fk_mm_q4

RADIAL_L_MM_Q4 = 109 * 16  # outer ring diameter L (000)
DUAL_PLUS_D_ACT_MM_Q4 = 757  # 47.3 mm in Q4 (000)
RING_D_MM_Q4 = 232  # 14.5 mm in Q4 (002)
# 002's guidance board as we built it (002 gives no sizes; docs/markers.md): cross centres 130 mm
# apart, the cylinder's axis 150 mm in front of the board's centre
CROSS_SPACING_MM_Q4 = 130 * 16
BOARD_BEHIND_MM_Q4 = 150 * 16


@dataclass(frozen=True)
class CameraModel:
    """Pinhole intrinsics in px: 000 f = 611, 002 f = 350, (u0, v0) = (160, 120)."""

    f_px: int = 611
    u0_px: int = 160
    v0_px: int = 120


CAMERA_000 = CameraModel(611, 160, 120)
CAMERA_002 = CameraModel(350, 160, 120)


def field(det: Any, *names: str) -> int | None:
    """The first of ``names`` present on a detection (attribute or dict key), as int."""
    for n in names:
        v = det.get(n) if isinstance(det, dict) else getattr(det, n, None)
        if v is not None:
            if isinstance(v, bool) or not isinstance(v, int | float):
                raise ValueError(f"detection field {n} is not a number: {v!r}")
            return int(v)
    return None


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


def _depth(size_mm_q4: int, f_px: int, d_q4: int) -> int | None:
    """Y = size f / d, all Q4 in and out; None for a non-positive d."""
    if d_q4 <= 0:
        return None
    return size_mm_q4 * f_px * 16 // d_q4


def object_in_platform(name: str, det: Any, geom: ArmGeometry, joints_mrad: tuple[int, ...],
                       cam: CameraModel) -> tuple[int, int, int] | None:
    """Object (marker centre) position in the platform frame, Q4 mm; None if not usable."""
    if det is None:
        return None
    if name == "radial_symbol":
        u, v = field(det, "u_q4", "u_r_q4"), field(det, "v_q4", "v_r_q4")
        y_mm = field(det, "y_oc_mm", "depth_mm")
        depth = y_mm * 16 if y_mm is not None else _depth(
            RADIAL_L_MM_Q4, cam.f_px, field(det, "diameter_q4", "d_q4", "d_px_q4") or 0)
    elif name == "dual_plus":
        u1, u2 = field(det, "u1_q4"), field(det, "u2_q4")
        v1, v2 = field(det, "v1_q4"), field(det, "v2_q4")
        u = field(det, "um_q4") if u1 is None or u2 is None else (u1 + u2) // 2
        v = field(det, "vm_q4") if v1 is None or v2 is None else (v1 + v2) // 2
        d_is = field(det, "dist_mm", "d_is_mm")  # dist_mm: D1's foreshortening-corrected D_is
        depth = d_is * 16 if d_is is not None else _depth(
            DUAL_PLUS_D_ACT_MM_Q4, cam.f_px, field(det, "d_pixel_q4") or 0)
    elif name == "red_cylinder":
        u, v = field(det, "uc_q4", "u_c_q4", "u_q4"), field(det, "vc_q4", "v_c_q4", "v_q4")
        depth = _depth(RING_D_MM_Q4, cam.f_px, field(det, "d_pixel_q4") or 0)
    elif name == "double_cross":
        # the cylinder, not the board: the board faces the robot, so the cylinder is about
        # BOARD_BEHIND closer along the line of sight (the board's row is used: the camera
        # looks level in the approach, so the ray is nearly horizontal)
        u, v = field(det, "um_q4"), field(det, "vm_q4")
        board = _depth(CROSS_SPACING_MM_Q4, cam.f_px, field(det, "d_pixel_q4") or 0)
        depth = board - BOARD_BEHIND_MM_Q4 if board is not None else None
    else:
        raise ValueError(f"no object position from detector {name!r}")
    if u is None or v is None or depth is None or depth <= 0:
        return None
    return pixel_to_platform_mm_q4(geom, joints_mrad, cam, u, v, depth)


def plus_positions(det: Any, geom: ArmGeometry, joints_mrad: tuple[int, ...],
                   cam: CameraModel) -> tuple[tuple[int, int, int], ...] | None:
    """Both "+" centres of a dual "+" detection in the platform frame (Q4 mm), at its depth."""
    u1, v1, u2, v2 = (field(det, n) for n in ("u1_q4", "v1_q4", "u2_q4", "v2_q4"))
    centre = object_in_platform("dual_plus", det, geom, joints_mrad, cam)
    if None in (u1, v1, u2, v2) or centre is None:
        return None
    d_is = field(det, "dist_mm", "d_is_mm")
    depth = d_is * 16 if d_is is not None else _depth(
        DUAL_PLUS_D_ACT_MM_Q4, cam.f_px, field(det, "d_pixel_q4") or 0)
    if depth is None:
        return None
    return (pixel_to_platform_mm_q4(geom, joints_mrad, cam, u1, v1, depth),
            pixel_to_platform_mm_q4(geom, joints_mrad, cam, u2, v2, depth))


def bearing_mrad(det: Any, theta5_mrad: int, cam: CameraModel) -> int | None:
    """002's e: bearing of the marker midpoint from the platform heading, right positive.

    Computed from the pixel column and the waist yaw (the image is not turned by the pitch for
    a level roll), so it does not depend on the yaw the detector was given."""
    um = field(det, "um_q4", "u_q4")
    if um is None:
        return None
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
    from mobigrasp.host.kinematics import spoke_angle_mrad

    if det is None:
        return None
    ang = field(det, "angle_mrad", "k_mrad", "slope_mrad")
    if ang is None:
        k = field(det, "k_q12", "slope_q12", "k_t_q12")
        if k is None:
            return None
        ang = spoke_angle_mrad(k)
    w = field(det, "w_px", "width_px")
    if w is None:
        wq = field(det, "w_q4", "width_q4")
        if wq is None:
            return None
        w = (wq + 8) // 16
    return ang, w


def d_pixel_px(det: Any) -> int | None:
    """Ring spacing d_pixel of the red cylinder (002 §2.2), or the spacing of the double
    cross's two crosses, in whole px."""
    if det is None:
        return None
    d = field(det, "d_pixel_q4")
    if d is not None:
        return (d + 8) // 16
    return field(det, "d_pixel", "d_pixel_px")
