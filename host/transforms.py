"""Camera -> platform transform of paper 000, eqs. (1)-(3), in fixed point.

Frames (docs/conventions.md): platform O_r with X_r right, Y_r forward, Z_r up, origin on the
waist axis at shoulder height; θ5 (waist) > 0 turns the arm to the right; α = θ2 + θ3 + θ4 is
the pitch of the last link and of the optical axis, positive up. The code's camera frame is
OpenCV's (x right, y down, z along the optical axis); the paper's camera frame has Y_c along
the optical axis, X_c to the left and Z_c up (:func:`paper_cam_to_cv` converts).

How the printed equations map:

- Eq. (3), the camera position P_cr: used as printed (``mobigrasp.host.kinematics.fk_mm_q4``):
  r = l1 cos θ4 + l2 cos(θ4 + θ3) + l3 cos α, P_crx = r sin θ5, P_cry = r cos θ5,
  P_crz = l1 sin θ4 + l2 sin(θ4 + θ3) + l3 sin α.
- Eq. (1), R_c^r = Rz(θ5) · [[1, 0, 0], [0, cos α, sin α], [0, -sin α, cos α]] = Rz(θ5) Rx(-α).
  With eq. (3)'s signs (θ5 > 0 moves the camera to +X, i.e. right) the yaw that turns forward
  (0, 1, 0) into (sin θ5, cos θ5, 0) is Rz(-θ5), and a pitch α > 0 that lifts the optical axis
  is Rx(+α). The printed matrix is the same physical rotation written for the mirrored X axis
  (X_c to the left: mirroring X flips the sign of both angles), which is the paper's camera
  frame. We use R_c^r = Rz(-θ5) · Rx(α) · C, where C takes OpenCV axes to the level camera
  (x -> X right, z -> Y forward, y -> -Z).
- Eq. (2), P_or = R_c^r P_oc + P_cr: as printed.

The wrist roll θ1 is taken as 0 (it is 0 except in the precise grasp of 000, which works on
image angles, not on this transform).
"""

from __future__ import annotations

from collections.abc import Sequence

from mobigrasp.host import arm_calib
from mobigrasp.host import fixedpoint as fp
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.kinematics import ArmGeometry, fk_mm_q4

# OpenCV camera axes -> level camera in platform axes: x -> X, y -> -Z, z -> Y (Q12)
C_CV_TO_LEVEL_Q12: fp.MatQ12 = ((fp.ONE_Q12, 0, 0), (0, 0, fp.ONE_Q12), (0, -fp.ONE_Q12, 0))


def paper_cam_to_cv(x_oc: int, y_oc: int, z_oc: int) -> tuple[int, int, int]:
    """Paper camera axes (X left, Y optical axis, Z up) -> OpenCV axes (x right, y down, z)."""
    return -int(x_oc), -int(z_oc), int(y_oc)


def r_c_r_q12(alpha_mrad: int, theta5_mrad: int) -> fp.MatQ12:
    """R_c^r of eq. (1) for OpenCV camera axes, Q12 (see the module docstring for the signs)."""
    return fp.matmul_q12(fp.matmul_q12(fp.rot_z_q12(-int(theta5_mrad)),
                                       fp.rot_x_q12(int(alpha_mrad))), C_CV_TO_LEVEL_Q12)


def camera_position_mm(geom: ArmGeometry, theta2_mrad: int, theta3_mrad: int, theta4_mrad: int,
                       theta5_mrad: int) -> tuple[int, int, int]:
    """P_cr of eq. (3) in whole mm (platform frame)."""
    x, y, z = fk_mm_q4(geom, theta2_mrad, theta3_mrad, theta4_mrad, theta5_mrad)
    return (x + 8) >> 4, (y + 8) >> 4, (z + 8) >> 4


def camera_to_platform_mm(p_cv_mm: Sequence[int], geom: ArmGeometry, theta2_mrad: int,
                          theta3_mrad: int, theta4_mrad: int,
                          theta5_mrad: int) -> tuple[int, int, int]:
    """Eq. (2): a point in OpenCV camera axes (mm) -> platform frame (mm), joints in mrad."""
    if len(p_cv_mm) != 3:
        raise ValueError(f"camera_to_platform_mm: expected 3 coordinates, got {len(p_cv_mm)}")
    alpha = int(theta2_mrad) + int(theta3_mrad) + int(theta4_mrad)
    rot = fp.matvec_q12(r_c_r_q12(alpha, theta5_mrad), tuple(int(v) for v in p_cv_mm))
    cr = camera_position_mm(geom, theta2_mrad, theta3_mrad, theta4_mrad, theta5_mrad)
    return rot[0] + cr[0], rot[1] + cr[1], rot[2] + cr[2]


def platform_offset_to_platform_mm(offset_mm: Sequence[int], geom: ArmGeometry,
                                   theta2_mrad: int, theta3_mrad: int, theta4_mrad: int,
                                   theta5_mrad: int) -> tuple[int, int, int]:
    """002's X_OR = X_OC + X_CR (§4): a camera-centred offset already in platform axes (as from
    host.ranging) plus the camera position of eq. (3)."""
    if len(offset_mm) != 3:
        raise ValueError(f"expected 3 coordinates, got {len(offset_mm)}")
    cr = camera_position_mm(geom, theta2_mrad, theta3_mrad, theta4_mrad, theta5_mrad)
    return tuple(int(o) + c for o, c in zip(offset_mm, cr, strict=True))  # type: ignore[return-value]


def camera_to_platform_from_servo_us(p_cv_mm: Sequence[int], geom: ArmGeometry,
                                     servo_us: Sequence[int]) -> tuple[int, int, int]:
    """Eq. (2) with the joint angles read from MCU telemetry: the six servo pulse widths (µs,
    index = channel, docs/conventions.md) through host.arm_calib's inverse servo law."""
    j = arm_calib.pulses_to_joints_mrad(tuple(int(p) for p in servo_us))
    return camera_to_platform_mm(p_cv_mm, geom, j[2], j[3], j[4], j[5])


def camera_to_platform_ops() -> OpCounts:
    """Cost of :func:`camera_to_platform_mm`: two rotations, two 3x3 products, one mat-vec,
    and eq. (3) (six sin/cos, a dozen multiplies)."""
    return (fp.rot_ops().scaled(2) + fp.matvec_ops().scaled(7) + fp.sin_ops().scaled(6)
            + OpCounts(muls32=12, alu=20))
