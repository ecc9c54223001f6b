"""Posture adjustment of the manipulator, 000 §III.B.2 (Fig. 4, eq. (10)): keep the object centred.

- Horizontal: ``d_theta5 = atan2(P_orx, P_ory) - theta5`` (the waist faces the object).
- Vertical: ``d_alpha = alpha' - alpha``, where alpha = theta2 + theta3 + theta4 is the pitch of
  the optical axis and alpha' the pitch of the line from the camera to the object (the paper
  leaves alpha' to Fig. 4; we take atan2(z_o - z_c, rho_o - r_c) with rho the horizontal distance
  from the waist axis, camera point by eq. (3)).  d_alpha is shared by the pitch joints by
  eq. (10): ``d_theta_i = d_alpha * k_i * theta_im / T_m``, ``T_m = sum_i k_i * theta_im``
  (i = 2, 3, 4) with 000's k_theta2 = 1, k_theta3 = k_theta4 = 0.
- Margins ``theta_im`` ("left margin amount"), as printed in 000 (its condition "|d_alpha| > 0"
  for the first case reads as d_alpha > 0, since the second is d_alpha <= 0)::

      d_alpha > 0:   theta2m = pi - theta2, theta3m = -theta3,     theta4m = -theta4
      d_alpha <= 0:  theta2m = theta2,      theta3m = pi + theta3, theta4m = pi + theta4

  The printed margins follow the paper's own sign conventions and can be negative with the
  joint table of docs/conventions.md (theta4 >= 0, theta2 <= 0), so ``margin_mode="limits"``
  offers the room to the joint limit in the direction of motion instead (hi - theta for
  d_alpha > 0, theta - lo otherwise).  With 000's k_theta (1, 0, 0) both modes give
  d_theta2 = d_alpha whenever theta2's margin is non-zero.  T_m = 0 means no room: no pitch change.

Integer only: angles in mrad, k_theta in Q12, positions in Q4 mm (host.kinematics).  The new
targets are clamped to the joint limits; the part of d_alpha lost to clamping is reported.
"""

from __future__ import annotations

from dataclasses import dataclass

from mobigrasp.host import arm_calib
from mobigrasp.host.fixedpoint import PI_MRAD, atan2_mrad, div_round, isqrt
from mobigrasp.host.kinematics import ArmGeometry, fk_mm_q4

MARGIN_MODES = ("printed", "limits")


@dataclass(frozen=True)
class PostureParams:
    """k_theta2..4 in Q12 (000 §IV: 1, 0, 0), the margin rule and an optional step limit."""

    k_theta_q12: tuple[int, int, int] = (4096, 0, 0)
    margin_mode: str = "printed"
    max_step_mrad: int = 0  # 0 = no limit per call; else |d_theta| per joint is capped

    def __post_init__(self) -> None:
        if self.margin_mode not in MARGIN_MODES:
            raise ValueError(f"margin_mode must be one of {MARGIN_MODES}, got {self.margin_mode!r}")
        if len(self.k_theta_q12) != 3 or any(k < 0 for k in self.k_theta_q12):
            raise ValueError(f"k_theta_q12 must be three non-negative ints, got {self.k_theta_q12}")
        if self.max_step_mrad < 0:
            raise ValueError(f"max_step_mrad must be >= 0, got {self.max_step_mrad}")


@dataclass(frozen=True)
class PostureAdjustment:
    """New joint targets (mrad, within limits) and what was asked for."""

    theta2_mrad: int
    theta3_mrad: int
    theta4_mrad: int
    theta5_mrad: int
    d_theta5_mrad: int
    d_alpha_mrad: int
    alpha_target_mrad: int
    alpha_lost_mrad: int  # part of d_alpha not applied (clamped or no margin)


def margins_mrad(d_alpha_mrad: int, theta2_mrad: int, theta3_mrad: int, theta4_mrad: int,
                 mode: str = "printed") -> tuple[int, int, int]:
    """The left margins theta_2m, theta_3m, theta_4m of 000 §III.B.2 (see module docstring)."""
    if mode == "printed":
        if d_alpha_mrad > 0:
            return PI_MRAD - theta2_mrad, -theta3_mrad, -theta4_mrad
        return theta2_mrad, PI_MRAD + theta3_mrad, PI_MRAD + theta4_mrad
    if mode == "limits":
        lim = arm_calib.JOINT_LIMITS_MRAD
        th = (theta2_mrad, theta3_mrad, theta4_mrad)
        if d_alpha_mrad > 0:
            return tuple(lim[ch][1] - t for ch, t in zip((2, 3, 4), th, strict=True))
        return tuple(t - lim[ch][0] for ch, t in zip((2, 3, 4), th, strict=True))
    raise ValueError(f"margin mode must be one of {MARGIN_MODES}, got {mode!r}")


def distribute_alpha(d_alpha_mrad: int, theta2_mrad: int, theta3_mrad: int, theta4_mrad: int,
                     params: PostureParams = PostureParams()) -> tuple[int, int, int]:
    """Eq. (10) of 000: d_theta_i = d_alpha * k_i * theta_im / T_m for i = 2, 3, 4."""
    m = margins_mrad(d_alpha_mrad, theta2_mrad, theta3_mrad, theta4_mrad, params.margin_mode)
    weights = [k * mi for k, mi in zip(params.k_theta_q12, m, strict=True)]
    t_m = sum(weights)
    if t_m == 0 or d_alpha_mrad == 0:
        return 0, 0, 0
    d = [div_round(d_alpha_mrad * w, t_m) for w in weights]
    # rounding: put the remainder on the joint with the largest weight so the sum is d_alpha
    sizes = [abs(w) for w in weights]
    biggest = sizes.index(max(sizes))  # the first of equal ones, as max(range(3), key=...)
    d[biggest] += d_alpha_mrad - sum(d)
    return d[0], d[1], d[2]


def desired_alpha_mrad(geom: ArmGeometry, theta2_mrad: int, theta3_mrad: int, theta4_mrad: int,
                       object_mm_q4: tuple[int, int, int]) -> int:
    """alpha': pitch of the line from the camera (eq. (3), waist facing the object) to it."""
    # camera radius and height with theta5 = 0: (x=0, y=r_c, z_c)
    _, r_c, z_c = fk_mm_q4(geom, theta2_mrad, theta3_mrad, theta4_mrad, 0)
    ox, oy, oz = object_mm_q4
    rho = isqrt(ox * ox + oy * oy)
    return atan2_mrad(oz - z_c, rho - r_c)


def _wrap_mrad(a: int) -> int:
    two_pi = 2 * PI_MRAD
    return (a + PI_MRAD) % two_pi - PI_MRAD


def _cap(v: int, cap: int) -> int:
    return v if cap == 0 else max(-cap, min(cap, v))


def adjust_posture(geom: ArmGeometry, joints_mrad: tuple[int, int, int, int],
                   object_mm_q4: tuple[int, int, int], params: PostureParams = PostureParams(),
                   alpha_target_mrad: int | None = None) -> PostureAdjustment:
    """One posture adjustment step from joints (theta2, theta3, theta4, theta5) and the object
    position in the platform frame (Q4 mm).  ``alpha_target_mrad`` overrides alpha'."""
    th2, th3, th4, th5 = map(int, joints_mrad)
    ox, oy, _ = object_mm_q4
    d5 = 0 if (ox == 0 and oy == 0) else _wrap_mrad(atan2_mrad(ox, oy) - th5)
    d5 = _cap(d5, params.max_step_mrad)
    alpha = th2 + th3 + th4
    a_target = (desired_alpha_mrad(geom, th2, th3, th4, object_mm_q4)
                if alpha_target_mrad is None else int(alpha_target_mrad))
    d_alpha = a_target - alpha
    d2, d3, d4 = distribute_alpha(d_alpha, th2, th3, th4, params)
    cap = params.max_step_mrad
    d2, d3, d4 = _cap(d2, cap), _cap(d3, cap), _cap(d4, cap)
    n2 = arm_calib.clamp_mrad(2, th2 + d2)
    n3 = arm_calib.clamp_mrad(3, th3 + d3)
    n4 = arm_calib.clamp_mrad(4, th4 + d4)
    n5 = arm_calib.clamp_mrad(5, th5 + d5)
    lost = d_alpha - ((n2 + n3 + n4) - alpha)
    return PostureAdjustment(n2, n3, n4, n5, d5, d_alpha, a_target, lost)
