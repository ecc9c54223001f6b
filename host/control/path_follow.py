"""Following a planned Bezier curve in time: feed-forward of eq. (8) of 000 plus integer feedback.

At plan time the curve (control points in the planners' 1/16 mm and 1/16 ms) is turned once
into an integer reference table (:class:`Trajectory`, :func:`reference_q`): per sample time
t_us, position in µm, heading in mrad, speed v in mm/s and yaw rate in mrad/s, all in integers
(``Trajectory.ops`` its cost).

Feed-forward, eq. (8) of 000: v_lw = v + w_w·l_w/2, v_rw = v − w_w·l_w/2 with
w_w = a_i sin(Δθ) / v. With Δθ measured counter-clockwise from the velocity to the acceleration,
a_i sin Δθ / v = v·κ is the counter-clockwise yaw rate ω, and a left turn needs the *right* wheel
faster; so 000's w_w is clockwise-positive (w_w = −ω). We write ω counter-clockwise (world
convention) and v_l = v − ω·l_w/2, v_r = v + ω·l_w/2, which is eq. (8) with w_w = −ω.

Feedback: the tracking law of Kanayama et al. (1990) on the odometry error in the robot frame,
all integer (errors in mm, angles in mrad, sine/cosine Q12):
    v = v_r cos e_θ + K_x e_x,    ω = ω_r + v_r (K_y e_y + K_θ sin e_θ).
Output wheel speeds in mm/s are scaled down together (keeping the turn) so that neither exceeds
``v_limit_mm_s`` (Vmax of the plan, never more than the SetWheels limit of 1000 mm/s).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.fixedpoint import (
    atan2_mrad,
    atan2_ops,
    cos_q12,
    div_round,
    isqrt,
    sin_ops,
    sin_q12,
)
from mobigrasp.host.odometry import TRACK_UM, Pose
from mobigrasp.host.planning.bezier import Curve
from mobigrasp.host.planning.bezier_q import (
    COORD_LIMIT,
    CURVE_SETUP_OPS,
    DIV64_OPS,
    ISQRT64_OPS,
    KAPPA_SAT,
    KAPPA_SCALE,
    POSITION_OPS,
    SAMPLE_BASE_OPS,
    TAU_BITS,
    coefficients_q,
    quantize_ctrl,
)

WHEEL_LIMIT_MM_S = 1000
HALF_TRACK_MM = TRACK_UM // 2000
# one sample of the reference (reference_q): the Horner steps of x, y, t and their derivatives,
# the root of s², four 64-bit quotients (v, |κ| twice, ω), the atan2 of the heading, the
# rounded conversions; and the curve's coefficients and call
SAMPLE_OPS = SAMPLE_BASE_OPS + POSITION_OPS + ISQRT64_OPS + DIV64_OPS.scaled(4) + atan2_ops() \
    + OpCounts(alu=40, muls32=3 * 3, branches=4)
CURVE_OPS = CURVE_SETUP_OPS
V_LIMIT_Q16 = 1 << 22  # 64 m/s
TRAJ_MAX_SAMPLES = 256  # the C table's capacity (hostc/path_follow.h)
# one step (PathFollower.step, eq. (8) with the Kanayama feedback): six 64-bit quotients on
# average (the reference's Q12 fraction and heading wrap, dx, dy, the feedback's ω term, the
# wheels' turn), four sin/cos, the products
STEP_OPS = DIV64_OPS.scaled(6) + sin_ops().scaled(4) + OpCounts(alu=80, muls32=10, branches=12)


def _half_away(num: int, shift: int) -> int:
    """num / 2^shift rounded, halves away from zero (the C's shifts of |num|)."""
    half = 1 << (shift - 1)
    return (num + half) >> shift if num >= 0 else -((half - num) >> shift)


def reference_q(ctrl_q, n: int) -> list[tuple[int, int, int, int, int, int]] | None:
    """The reference of one curve at τ_j = (j << 15) / (n − 1), from control points in 1/16 mm
    and 1/16 ms (bezier_q's formats; hostc/path_follow.c mg_trajectory_from_ctrl), per sample:
    t − t0 in µs, x and y in µm, the heading atan2(y_τ, x_τ) in mrad, v = s / t_τ in mm/s and
    the yaw rate ω = v κ in mrad/s with κ = (x_τ y_2τ − x_2τ y_τ) / s³ signed (eq. (7) of 000's
    derivatives; the curvature as the planners' check computes |κ|). None when t_τ <= 0 or
    s = 0 at a sample, a coordinate is 2^21 counts or more, a speed 64 m/s or more (which
    keeps v κ · 1000 within 63 bits), or n outside 2..TRAJ_MAX_SAMPLES."""
    ctrl = [[int(v) for v in row] for row in np.asarray(ctrl_q, dtype=np.int64).reshape(4, 3)]
    if n < 2 or n > TRAJ_MAX_SAMPLES or any(abs(v) >= COORD_LIMIT for row in ctrl for v in row):
        return None
    k = coefficients_q(np.asarray(ctrl, dtype=np.int64)[None])[0]
    coef = [[int(k[i, c]) for i in range(4)] for c in range(3)]
    rows = []
    for j in range(n):
        tau = (j << TAU_BITS) // (n - 1)
        (x, xt, x2), (y, yt, y2), (t, tt, _) = (_horner(c, tau) for c in coef)
        s = isqrt(xt * xt + yt * yt)
        if tt <= 0 or s == 0:
            return None
        cross = xt * y2 - x2 * yt
        kappa = min((((abs(cross) << 6) // s) * KAPPA_SCALE) // (s * s), KAPPA_SAT)
        v_q16 = (s << 16) // tt  # m/s Q16
        if v_q16 >= V_LIMIT_Q16:
            return None
        w = _half_away(v_q16 * kappa * 1000, 32)  # mrad/s
        rows.append((_half_away((t - ctrl[0][2]) * 125, 1), _half_away(x * 125, 1),
                      _half_away(y * 125, 1), atan2_mrad(yt, xt), div_round(s * 1000, tt),
                      w if cross >= 0 else -w))
    return rows


def _horner(k: list[int], tau: int) -> tuple[int, int, int]:
    """Position, first and second derivative at τ (Q15), bezier_q.horner_q on integers."""
    k0, k1, k2, k3 = k
    pos = k0 + ((tau * (k1 + ((tau * (k2 + ((tau * k3) >> TAU_BITS))) >> TAU_BITS)))
                >> TAU_BITS)
    d1 = k1 + ((tau * (2 * k2 + ((tau * (3 * k3)) >> TAU_BITS))) >> TAU_BITS)
    d2 = 2 * k2 + ((tau * (6 * k3)) >> TAU_BITS)
    return pos, d1, d2


def wrap_mrad(a: int) -> int:
    """Angle in mrad wrapped to [−3142, 3141] (2π = 6283 mrad)."""
    return (int(a) + 3142) % 6283 - 3142


@dataclass(frozen=True)
class Trajectory:
    """Integer reference table of one curve; times relative to the start of the curve."""

    t_us: tuple[int, ...]
    x_um: tuple[int, ...]
    y_um: tuple[int, ...]
    heading_mrad: tuple[int, ...]
    v_mm_s: tuple[int, ...]
    w_mrad_s: tuple[int, ...]  # counter-clockwise yaw rate v·κ
    ops: OpCounts

    @classmethod
    def from_curve(cls, curve: Curve, n_samples: int = 96) -> Trajectory:
        """Sample the curve at n equally spaced τ, in integers (:func:`reference_q`)."""
        return cls.from_ctrl_q(quantize_ctrl(curve.array), n_samples)

    @classmethod
    def from_ctrl_q(cls, ctrl_q, n_samples: int = 96) -> Trajectory:
        """The reference table of control points in 1/16 mm and 1/16 ms (:func:`reference_q`);
        ValueError when the curve's time does not increase or a coordinate is out of range."""
        rows = reference_q(ctrl_q, n_samples)
        if rows is None:
            raise ValueError("curve time is not increasing or out of range: cannot follow it")
        return cls(*(tuple(col) for col in zip(*rows, strict=True)),
                   ops=SAMPLE_OPS.scaled(n_samples) + CURVE_OPS)
    @property
    def duration_us(self) -> int:
        """Time of the last sample."""
        return self.t_us[-1]

    def at(self, t_us: int, hint: int = 0) -> tuple[int, int, int, int, int, int]:
        """Reference (x_um, y_um, heading_mrad, v_mm_s, w_mrad_s, index) at time t (linear)."""
        i = max(0, min(int(hint), len(self.t_us) - 2))
        while i > 0 and self.t_us[i] > t_us:
            i -= 1
        while i < len(self.t_us) - 2 and self.t_us[i + 1] <= t_us:
            i += 1
        t_a, t_b = self.t_us[i], self.t_us[i + 1]
        if t_us >= t_b:
            return (self.x_um[-1], self.y_um[-1], self.heading_mrad[-1], 0, 0, i)
        f = max(0, t_us - t_a) * 4096 // max(1, t_b - t_a)  # Q12 fraction of the segment

        def lerp(a: int, b: int) -> int:
            return a + ((b - a) * f >> 12)

        dh = wrap_mrad(self.heading_mrad[i + 1] - self.heading_mrad[i])
        return (lerp(self.x_um[i], self.x_um[i + 1]), lerp(self.y_um[i], self.y_um[i + 1]),
                wrap_mrad(self.heading_mrad[i] + (dh * f >> 12)),
                lerp(self.v_mm_s[i], self.v_mm_s[i + 1]),
                lerp(self.w_mrad_s[i], self.w_mrad_s[i + 1]), i)


@dataclass(frozen=True)
class WheelCommand:
    """Wheel speed targets (mm/s) for SetWheels, and whether the follower has finished."""

    left_mm_s: int
    right_mm_s: int
    done: bool = False
    error_mm: int = 0  # distance from the reference point


@dataclass(frozen=True)
class FollowGains:
    """Kanayama gains: K_x in 1/s (Q12), K_y in 1/m² and K_θ in 1/m (integers)."""

    k_x_q12: int = 6144  # 1.5 /s
    k_y_per_m2: int = 16
    k_theta_per_m: int = 8


def wheel_speeds(v_mm_s: int, w_mrad_s: int, limit_mm_s: int) -> tuple[int, int]:
    """Eq. (8) of 000 with ω counter-clockwise (w_w = −ω), scaled into ±limit keeping the turn."""
    turn = div_round(w_mrad_s * HALF_TRACK_MM, 1000)
    left, right = v_mm_s - turn, v_mm_s + turn
    limit = max(0, min(int(limit_mm_s), WHEEL_LIMIT_MM_S))
    peak = max(abs(left), abs(right))
    if peak > limit:
        left, right = div_round(left * limit, peak), div_round(right * limit, peak)
    return left, right


class PathFollower:
    """Tracks one Trajectory from ``start_us`` with odometry poses; integer per step."""

    def __init__(self, traj: Trajectory, start_us: int, v_limit_mm_s: int,
                 gains: FollowGains = FollowGains(), goal_tol_mm: int = 30,
                 overtime_us: int = 3_000_000) -> None:
        self.traj = traj
        self.start_us = int(start_us)
        self.v_limit_mm_s = int(v_limit_mm_s)
        self.gains = gains
        self.goal_tol_mm = int(goal_tol_mm)
        self.overtime_us = int(overtime_us)
        self._hint = 0
        self.steps = 0

    def step(self, t_us: int, pose: Pose) -> WheelCommand:
        """Wheel speeds for the pose at time t_us (simulated)."""
        self.steps += 1
        rel = int(t_us) - self.start_us
        xr, yr, hr, vr, wr, self._hint = self.traj.at(rel, self._hint)
        dx_mm = div_round(xr - pose.x_um, 1000)
        dy_mm = div_round(yr - pose.y_um, 1000)
        c, s = cos_q12(pose.heading_mrad), sin_q12(pose.heading_mrad)
        e_x = (c * dx_mm + s * dy_mm) >> 12  # along the robot, mm
        e_y = (-s * dx_mm + c * dy_mm) >> 12  # to the robot's left, mm
        e_th = wrap_mrad(hr - pose.heading_mrad)
        err_mm = max(abs(dx_mm), abs(dy_mm))
        finished = rel >= self.traj.duration_us
        if finished and (err_mm <= self.goal_tol_mm or rel >= self.traj.duration_us
                         + self.overtime_us):
            return WheelCommand(0, 0, True, err_mm)
        g = self.gains
        v = (vr * cos_q12(e_th) >> 12) + (g.k_x_q12 * e_x >> 12)
        w = wr + div_round(vr * g.k_y_per_m2 * e_y, 1000) \
            + (vr * g.k_theta_per_m * sin_q12(e_th) >> 12)
        if finished:  # past the end: creep to the final point, turning toward it
            v = max(-60, min(60, g.k_x_q12 * e_x >> 12))
            w = 2 * atan2_mrad(e_y, max(1, abs(e_x))) if err_mm > 5 else 0
        left, right = wheel_speeds(v, w, self.v_limit_mm_s)
        return WheelCommand(left, right, False, err_mm)
