"""Arm forward and inverse kinematics in fixed point: eq. (3) and (11) of 000, eq. (4) of 002.

Numbering and frames follow docs/conventions.md (paper 000 numbering): theta4 = shoulder,
theta3 = elbow, theta2 = wrist pitch, theta5 = waist yaw, theta1 = wrist roll; pitch angles from
the horizontal, positive up; alpha = theta2 + theta3 + theta4 is the pitch of the last link l3.
Platform frame O_r: Y_r forward, X_r right, Z_r up, origin on the waist axis at shoulder height.

Units: angles are integer mrad; positions and link lengths are integer millimetres in Q4
(1/16 mm, ``_mm_q4``) so that the round trip FK(IK(p)) stays well inside 1 mm; sin/cos are Q12
from host.fixedpoint.  Products of two Q4 lengths need 64-bit integers on the ARM (long long).

- FK, eq. (3) of 000:  r = l1 cos th4 + l2 cos(th4 + th3) + l3 cos(alpha);
  P_crx = r sin th5, P_cry = r cos th5, P_crz = l1 sin th4 + l2 sin(th4 + th3) + l3 sin(alpha).
- IK with the pitch of l3 fixed to alpha_T, eq. (11) of 000:
  th3 = -acos((A^2 + B^2 - l1^2 - l2^2) / (2 l1 l2)),
  th4 = acos(((l1 + l2 cos th3) A + l2 sin th3 B) / (l1^2 + l2^2 + 2 l1 l2 cos th3)),
  th2 = alpha_T - th3 - th4, th5 = atan2(P_orx, P_ory).
  As printed, A = P_ory / cos th5 - l3 and B = P_orz, which is the wrist point only for a
  horizontal last link (alpha_T = 0; the same formula is eq. (4) of 002).  For a general alpha_T
  the wrist point is A = r - l3 cos(alpha_T), B = P_orz - l3 sin(alpha_T), which reduces to the
  printed one at alpha_T = 0; for the rough grasp of 000 (alpha_T = -pi/2) it is A = r,
  B = P_orz + l3.  We use r = sqrt(P_orx^2 + P_ory^2) (equal to P_ory / cos th5, without the
  division by a small cosine), and th4 by atan2 of the exact sine and cosine numerators, which
  equals the printed acos on the limits [0, 3.0] rad and keeps the sign outside them.
- Paper 002 numbers the joints differently: its th1, th2, th3 (shoulder, elbow, wrist pitch) and
  th4 (waist) are our th4, th3, th2 and th5, and its horizontal-gripper constraint
  th1 + th2 + th3 = 0 is alpha = 0 here; its l1, l2, l3 = 97, 89, 95.5 mm are ours in the same
  order (the first link from the waist is l1).  :func:`ik_horizontal_002` solves eq. (4) of 002.

An unreachable target gives :class:`Unreachable` naming why; a returned :class:`ArmPose` is
always inside the joint limits of host.arm_calib.
"""

from __future__ import annotations

from dataclasses import dataclass

from mobigrasp.host import arm_calib
from mobigrasp.host.fixedpoint import atan2_urad, cos_q12, isqrt, sin_q12

Q4 = 16  # 1 mm in Q4
ALPHA_DOWN_MRAD = -1571  # alpha_T = -pi/2: gripper vertical, looking down (000)
ALPHA_LEVEL_MRAD = 0  # horizontal gripper (002)
REACH_TOL_MM_Q4 = 8  # 0.5 mm: rounding slack at the workspace boundary
LIMIT_SNAP_MRAD = 30  # theta3..5 this close outside a limit are put on it (FK-checked after)
ALPHA_SNAP_MRAD = 30  # theta2 too: alpha stays within 30 mrad of alpha_T (FK-checked)


@dataclass(frozen=True)
class ArmGeometry:
    """Link lengths l1 (shoulder), l2 (elbow), l3 (wrist to camera/gripper point) in Q4 mm."""

    l1_mm_q4: int
    l2_mm_q4: int
    l3_mm_q4: int

    def __post_init__(self) -> None:
        for name in ("l1_mm_q4", "l2_mm_q4", "l3_mm_q4"):
            v = getattr(self, name)
            if not isinstance(v, int) or v <= 0:
                raise ValueError(f"{name} must be a positive int, got {v!r}")

    @classmethod
    def from_mm(cls, l1_mm: float, l2_mm: float, l3_mm: float) -> ArmGeometry:
        """Configuration-time conversion of link lengths in mm (e.g. 95.5) to Q4 mm."""
        return cls(*(int(round(float(v) * Q4)) for v in (l1_mm, l2_mm, l3_mm)))


PAPER_000 = ArmGeometry.from_mm(95.5, 89.0, 97.0)
PAPER_002 = ArmGeometry.from_mm(97.0, 89.0, 95.5)


@dataclass(frozen=True)
class ArmPose:
    """Pitch/yaw joint angles in mrad (conventions numbering)."""

    theta2_mrad: int
    theta3_mrad: int
    theta4_mrad: int
    theta5_mrad: int

    @property
    def alpha_mrad(self) -> int:
        return self.theta2_mrad + self.theta3_mrad + self.theta4_mrad


@dataclass(frozen=True)
class Unreachable:
    """The target cannot be reached; ``reason`` says why (joint and value, or distance)."""

    reason: str


def _round_q12(v: int) -> int:
    return (v + 2048) >> 12


def _urad_to_mrad(u: int) -> int:
    return (u + 500) // 1000 if u >= 0 else -((-u + 500) // 1000)


def fk_mm_q4(geom: ArmGeometry, theta2_mrad: int, theta3_mrad: int, theta4_mrad: int,
             theta5_mrad: int) -> tuple[int, int, int]:
    """Camera/gripper point (P_crx, P_cry, P_crz) in Q4 mm, eq. (3) of 000."""
    t43 = theta4_mrad + theta3_mrad
    alpha = t43 + theta2_mrad
    r = _round_q12(geom.l1_mm_q4 * cos_q12(theta4_mrad) + geom.l2_mm_q4 * cos_q12(t43)
                   + geom.l3_mm_q4 * cos_q12(alpha))
    z = _round_q12(geom.l1_mm_q4 * sin_q12(theta4_mrad) + geom.l2_mm_q4 * sin_q12(t43)
                   + geom.l3_mm_q4 * sin_q12(alpha))
    return _round_q12(r * sin_q12(theta5_mrad)), _round_q12(r * cos_q12(theta5_mrad)), z


def fk_pose_mm_q4(geom: ArmGeometry, pose: ArmPose) -> tuple[int, int, int]:
    """:func:`fk_mm_q4` of an :class:`ArmPose`."""
    return fk_mm_q4(geom, pose.theta2_mrad, pose.theta3_mrad, pose.theta4_mrad, pose.theta5_mrad)


def fk_mm(geom: ArmGeometry, theta2_mrad: int, theta3_mrad: int, theta4_mrad: int,
          theta5_mrad: int) -> tuple[int, int, int]:
    """Eq. (3) of 000 rounded to whole mm."""
    return tuple((v + 8) >> 4 for v in fk_mm_q4(geom, theta2_mrad, theta3_mrad, theta4_mrad,
                                                theta5_mrad))


def _check_limits(pose: ArmPose) -> Unreachable | None:
    for ch, val in ((2, pose.theta2_mrad), (3, pose.theta3_mrad), (4, pose.theta4_mrad),
                    (5, pose.theta5_mrad)):
        lo, hi = arm_calib.JOINT_LIMITS_MRAD[ch]
        if not lo <= val <= hi:
            return Unreachable(
                f"theta{ch} ({arm_calib.JOINT_NAMES[ch]}) would be {val} mrad, "
                f"outside [{lo}, {hi}] mrad")
    return None


def ik_pitch_mm_q4(geom: ArmGeometry, target_mm_q4: tuple[int, int, int],
                   alpha_t_mrad: int) -> ArmPose | Unreachable:
    """Joint angles putting the camera/gripper point at ``target`` with l3 pitched at alpha_T.

    Eq. (11) of 000 generalised to any alpha_T (module docstring); integer arithmetic only.
    """
    x, y, z = (int(v) for v in target_mm_q4)
    if x == 0 and y == 0:
        return Unreachable("target on the waist axis: waist angle undefined")
    theta5_u = atan2_urad(x, y)  # th5 = atan2(P_orx, P_ory)
    r = isqrt(x * x + y * y)  # = P_ory / cos th5
    # Behind the waist axis the yaw limits (+-1.4 rad) forbid facing the target; the arm can
    # still reach it over the shoulder (th4 > pi/2) with the waist turned by pi and r < 0.
    if abs(theta5_u) > 1000 * (arm_calib.JOINT_LIMITS_MRAD[5][1] + LIMIT_SNAP_MRAD):
        theta5_u -= 3_141_593 if theta5_u > 0 else -3_141_593
        r = -r
    theta5 = _urad_to_mrad(theta5_u)
    l1, l2, l3 = geom.l1_mm_q4, geom.l2_mm_q4, geom.l3_mm_q4
    a = r - _round_q12(l3 * cos_q12(alpha_t_mrad))
    b = z - _round_q12(l3 * sin_q12(alpha_t_mrad))
    d2 = a * a + b * b
    num = d2 - l1 * l1 - l2 * l2  # cos th3 = num / den
    den = 2 * l1 * l2
    # A target within REACH_TOL of the boundary (rounding of a stretched or folded pose) is
    # taken onto the boundary rather than refused.
    if den < num <= (2 * (l1 + l2) + REACH_TOL_MM_Q4) * REACH_TOL_MM_Q4 + den:
        num = den
    elif -den > num >= -den - (2 * abs(l1 - l2) + REACH_TOL_MM_Q4) * REACH_TOL_MM_Q4:
        num = -den
    if num > den:
        return Unreachable(
            f"out of reach: wrist point {isqrt(d2) / Q4:.1f} mm from the shoulder > "
            f"l1 + l2 = {(l1 + l2) / Q4:.1f} mm")
    if num < -den:
        return Unreachable(
            f"too close: wrist point {isqrt(d2) / Q4:.1f} mm from the shoulder < "
            f"|l1 - l2| = {abs(l1 - l2) / Q4:.1f} mm")
    sin_den = isqrt(den * den - num * num)  # |sin th3| * den
    theta3_u = -atan2_urad(sin_den, num)  # th3 = -acos(num / den), elbow in [-pi, 0]
    # th4 from cos and sin numerators: k1 = l1 + l2 cos th3, k2 = l2 sin th3 (both times den)
    k1 = l1 * den + l2 * num
    k2 = -l2 * sin_den
    theta4_u = atan2_urad(k1 * b - k2 * a, k1 * a + k2 * b)
    # Near a limit (e.g. the stretched arm, where acos is ill-conditioned and 1/32 mm of input
    # rounding moves the elbow by tens of mrad) a solution just outside is pulled onto the
    # limit; the FK check below keeps the point within 1 mm.
    theta3 = _snap_to_limit(3, _urad_to_mrad(theta3_u))
    theta4 = _snap_to_limit(4, _urad_to_mrad(theta4_u))
    pose = ArmPose(_snap_to_limit(2, alpha_t_mrad - theta3 - theta4, ALPHA_SNAP_MRAD), theta3,
                   theta4, _snap_to_limit(5, theta5))
    bad = _check_limits(pose)
    if bad is not None:
        return bad
    # The snap may move the point: guarantee the returned pose is within 1 mm of the target.
    px, py, pz = fk_pose_mm_q4(geom, pose)
    err2 = (px - x) ** 2 + (py - y) ** 2 + (pz - z) ** 2
    if err2 > Q4 * Q4:
        return Unreachable(f"at the joint limits the point misses the target by "
                           f"{isqrt(err2) / Q4:.1f} mm")
    return pose


def _snap_to_limit(ch: int, angle_mrad: int, snap_mrad: int = LIMIT_SNAP_MRAD) -> int:
    lo, hi = arm_calib.JOINT_LIMITS_MRAD[ch]
    if lo - snap_mrad <= angle_mrad < lo:
        return lo
    if hi < angle_mrad <= hi + snap_mrad:
        return hi
    return angle_mrad


def ik_rough_grasp_000(geom: ArmGeometry, target_mm_q4: tuple[int, int, int],
                       alpha_t_mrad: int = ALPHA_DOWN_MRAD) -> ArmPose | Unreachable:
    """Rough grasp of 000 §III.C.1: eq. (11) with alpha = alpha_T = -pi/2 (gripper down)."""
    return ik_pitch_mm_q4(geom, target_mm_q4, alpha_t_mrad)


def ik_horizontal_002(geom: ArmGeometry,
                      target_mm_q4: tuple[int, int, int]) -> ArmPose | Unreachable:
    """Eq. (4) of 002: horizontal gripper (002's th1 + th2 + th3 = 0, i.e. alpha = 0 here)."""
    return ik_pitch_mm_q4(geom, target_mm_q4, ALPHA_LEVEL_MRAD)


def pose_in_002_numbering(pose: ArmPose) -> dict[str, int]:
    """The same pose with 002's joint names (th1 shoulder, th2 elbow, th3 wrist, th4 waist)."""
    return {"theta1_mrad": pose.theta4_mrad, "theta2_mrad": pose.theta3_mrad,
            "theta3_mrad": pose.theta2_mrad, "theta4_mrad": pose.theta5_mrad}


def mm_to_q4(p_mm: tuple[int, int, int]) -> tuple[int, int, int]:
    """Integer mm to Q4 mm."""
    return tuple(int(v) * Q4 for v in p_mm)


# --- precise grasp helpers (000 §III.C.2) ----------------------------------------------------
ROLL_PRECISE_MRAD = 1571  # th1 rotates by pi/2 once the gripper is above the object
W_MIN_PX = 20  # w_min, w_max of 000 §IV
W_MAX_PX = 40
QUARTER_TURN_MRAD = 1571


@dataclass(frozen=True)
class PreciseGraspStep:
    """One step of the precise grasp: new roll and waist targets, a height change, and whether
    the gripper may go down (k_T = 0 and w_T in [w_min, w_max])."""

    theta1_mrad: int
    theta5_mrad: int
    dz_mm: int
    aligned: bool
    reason: str
    d_align_mrad: int = 0  # the turn asked for (applied to theta5 here; the caller may roll)


def spoke_angle_mrad(slope_q12: int) -> int:
    """Image angle of a spoke with slope k_T (Q12), in mrad, in (-pi/2, pi/2)."""
    return _urad_to_mrad(atan2_urad(slope_q12, 4096))


def _wrap_quarter(angle_mrad: int) -> int:
    """The "+" has four spokes 90 degrees apart: fold an angle into [-pi/4, pi/4)."""
    q = QUARTER_TURN_MRAD
    return (angle_mrad + q // 2) % q - q // 2


def precise_grasp_step(theta5_mrad: int, spoke_mrad: int, width_px: int, *,
                       slope_tol_mrad: int = 35, max_step_mrad: int = 150,
                       yaw_sign: int = 1, dz_step_mm: int = 10,
                       w_min_px: int = W_MIN_PX, w_max_px: int = W_MAX_PX) -> PreciseGraspStep:
    """Roll to pi/2, drive the spoke slope k_T to 0 with th5, check w_T (000 §III.C.2).

    ``spoke_mrad`` is the spoke's image angle (atan k_T), folded modulo a quarter turn.  With the
    camera looking down, turning the waist by d rotates the image by -d (``yaw_sign`` = +1 means
    a positive image angle is removed by a positive waist step).  A narrow spoke means the camera
    is too high (lower by ``dz_step_mm``), a wide one too low (raise).
    """
    ang = _wrap_quarter(int(spoke_mrad))
    step = max(-max_step_mrad, min(max_step_mrad, yaw_sign * ang))
    th5 = arm_calib.clamp_mrad(5, theta5_mrad + (step if abs(ang) > slope_tol_mrad else 0))
    if width_px < w_min_px:
        dz, wreason = -dz_step_mm, f"w_T {width_px} px < {w_min_px}: lower"
    elif width_px > w_max_px:
        dz, wreason = dz_step_mm, f"w_T {width_px} px > {w_max_px}: raise"
    else:
        dz, wreason = 0, f"w_T {width_px} px in range"
    slope_ok = abs(ang) <= slope_tol_mrad
    aligned = slope_ok and dz == 0
    sreason = "k_T ~ 0" if slope_ok else f"spoke at {ang} mrad: turn"
    return PreciseGraspStep(ROLL_PRECISE_MRAD, th5, dz, aligned, f"{sreason}; {wreason}",
                            0 if slope_ok else step)
