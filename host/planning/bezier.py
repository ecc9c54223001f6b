"""Cubic Bezier curves with time as third coordinate (000 eqs. (4)-(7); 001 (3)-(4), (12)-(14)).

A curve has four control points ``(x_i, y_i, t_i)`` (metres, metres, seconds). Eq. (5) of 000 /
(3) of 001 is the Bernstein form; eq. (6) of 000 / (4) of 001 its power form with coefficients
``a_i, b_i, c_i``; eq. (7) of 000 / (12)-(13) of 001 the first and second derivatives in τ.
From them, per sample τ_j = j/(n-1):

- speed ``v = |(x_τ, y_τ)| / t_τ`` (000 §III.B.1, 001 §III.C.1);
- tangential acceleration ``a_t = dv/dt`` (the projection of 000's acceleration vector
  ``(dv_x/dt, dv_y/dt)`` on the velocity) and the normal part ``a_n = v²κ`` (what 001 eq. (14)
  calls "tangent acceleration");
- signed curvature ``κ = (x_τ y_2τ − x_2τ y_τ) / (x_τ² + y_τ²)^{3/2}`` (000 eq. under (8), 001
  below (14)), positive for a left (counter-clockwise) turn; the papers use |κ|;
- arc length ``∫ |(x_τ, y_τ)| dτ`` and ``∫ |κ| dτ`` (trapezoid rule over the samples), the two
  terms of eq. (9) of 000 / (17) of 001.

Everything here is numpy float64: the reference the planners' fixed-point evaluation
(:mod:`mobigrasp.host.planning.bezier_q`, hostc/bezier.c) is tested against, and the curve the
path follower's table is built from.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mobigrasp.protocol.frozen import built


def coefficients(ctrl: np.ndarray) -> np.ndarray:
    """Power-form coefficients of eq. (6) of 000: ``k[..., i, c]`` for τ^i of coordinate c.

    ``ctrl`` has shape (..., 4, 3) with columns (x, y, t); the result has the same shape and
    holds (a_i, b_i, c_i) in its columns. Expanding eq. (5):
    k0 = P0, k1 = 3(P1 − P0), k2 = 3(P0 − 2P1 + P2), k3 = −P0 + 3P1 − 3P2 + P3.
    """
    ctrl = np.asarray(ctrl, dtype=np.float64)
    p0, p1, p2, p3 = (ctrl[..., i, :] for i in range(4))
    return np.stack([p0, 3.0 * (p1 - p0), 3.0 * (p0 - 2.0 * p1 + p2),
                     -p0 + 3.0 * p1 - 3.0 * p2 + p3], axis=-2)


@dataclass(frozen=True)
class Samples:
    """A curve (or a batch of curves, leading axis) sampled at ``tau``; SI units."""

    tau: np.ndarray
    x: np.ndarray
    y: np.ndarray
    t: np.ndarray
    x_tau: np.ndarray
    y_tau: np.ndarray
    t_tau: np.ndarray
    x_2tau: np.ndarray
    y_2tau: np.ndarray
    t_2tau: np.ndarray
    speed: np.ndarray  # v = |(x_τ, y_τ)| / t_τ, m/s
    accel_tangential: np.ndarray  # dv/dt, m/s²
    kappa: np.ndarray  # signed curvature, 1/m, > 0 turning left
    ds_dtau: np.ndarray  # |(x_τ, y_τ)|, m per unit τ

    @property
    def accel_normal(self) -> np.ndarray:
        """v²|κ|, the quantity eq. (14) of 001 calls the tangent acceleration (m/s²)."""
        return self.speed**2 * np.abs(self.kappa)

    @property
    def omega(self) -> np.ndarray:
        """Yaw rate v·κ in rad/s, counter-clockwise positive (= a·sinΔθ/v of eq. (8) of 000)."""
        return self.speed * self.kappa

    @property
    def heading(self) -> np.ndarray:
        """Direction of travel atan2(y_τ, x_τ), rad."""
        return np.arctan2(self.y_tau, self.x_tau)

    def arc_length(self) -> np.ndarray:
        """∫₀¹ |(x_τ, y_τ)| dτ by the trapezoid rule (metres)."""
        return _trapezoid(self.ds_dtau, self.tau)

    def kappa_integral(self) -> np.ndarray:
        """∫₀¹ |κ(τ)| dτ by the trapezoid rule (as eq. (9) of 000 writes it: over τ, not s)."""
        return _trapezoid(np.abs(self.kappa), self.tau)


def _trapezoid(f: np.ndarray, tau: np.ndarray) -> np.ndarray:
    d = np.diff(tau)
    return np.sum(0.5 * (f[..., 1:] + f[..., :-1]) * d, axis=-1)


def taus(n_samples: int) -> np.ndarray:
    """The sample parameters τ_j = j / (n − 1), j = 0..n−1 (n >= 2)."""
    if n_samples < 2:
        raise ValueError(f"n_samples must be >= 2, got {n_samples}")
    return np.linspace(0.0, 1.0, int(n_samples))


def evaluate(ctrl: np.ndarray, tau: np.ndarray) -> Samples:
    """Evaluate eqs. (6)-(7) of 000 for control points ``ctrl`` (..., 4, 3) at parameters ``tau``.

    Where t_τ <= 0 or the curve stops (|(x_τ, y_τ)| = 0) the derived quantities are inf/nan; the
    planners reject such samples explicitly.
    """
    k = coefficients(ctrl)
    tau = np.asarray(tau, dtype=np.float64)
    one, zero = np.ones_like(tau), np.zeros_like(tau)
    # power bases of eqs. (6)-(7): position, first and second derivative, one matmul each
    b0 = np.stack([one, tau, tau**2, tau**3], axis=-1)
    b1 = np.stack([zero, one, 2.0 * tau, 3.0 * tau**2], axis=-1)
    b2 = np.stack([zero, zero, 2.0 * one, 6.0 * tau], axis=-1)
    kt = np.moveaxis(k, -1, -2)  # (..., 3, 4): coordinate, power
    pos = kt @ b0.T  # (..., 3, n)
    d1 = kt @ b1.T
    d2 = kt @ b2.T
    x_t, y_t, t_t = d1[..., 0, :], d1[..., 1, :], d1[..., 2, :]
    x_2t, y_2t, t_2t = d2[..., 0, :], d2[..., 1, :], d2[..., 2, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.hypot(x_t, y_t)
        v = s / t_t
        s_dot = (x_t * x_2t + y_t * y_2t) / s  # d|P_τ|/dτ
        dv_dtau = (s_dot * t_t - s * t_2t) / t_t**2
        a_t = dv_dtau / t_t
        kappa = (x_t * y_2t - x_2t * y_t) / s**3
    return Samples(tau=tau, x=pos[..., 0, :], y=pos[..., 1, :], t=pos[..., 2, :], x_tau=x_t,
                   y_tau=y_t, t_tau=t_t, x_2tau=x_2t, y_2tau=y_2t, t_2tau=t_2t, speed=v,
                   accel_tangential=a_t, kappa=kappa, ds_dtau=s)


@dataclass(frozen=True)
class Curve:
    """One cubic Bezier path with time: control points P0..P3 as rows (x_m, y_m, t_s)."""

    ctrl: tuple[tuple[float, float, float], ...]

    def __post_init__(self) -> None:
        arr = np.asarray(self.ctrl, dtype=np.float64)
        if arr.shape != (4, 3) or not np.all(np.isfinite(arr)):
            raise ValueError(f"Curve needs 4 finite (x, y, t) control points, got {self.ctrl!r}")

    @classmethod
    def from_array(cls, ctrl: np.ndarray) -> Curve:
        """Build from a (4, 3) array."""
        return cls(tuple(map(tuple, np.asarray(ctrl, dtype=np.float64).tolist())))

    @classmethod
    def batch_from_array(cls, ctrl: np.ndarray) -> list[Curve]:
        """Curves from an (N, 4, 3) array, validated once for the whole batch."""
        arr = np.asarray(ctrl, dtype=np.float64)
        if arr.ndim != 3 or arr.shape[1:] != (4, 3) or not np.all(np.isfinite(arr)):
            raise ValueError(f"need finite (N, 4, 3) control points, got shape {arr.shape}")
        out = []
        for rows in arr.tolist():
            out.append(built(cls, ctrl=tuple(map(tuple, rows))))
        return out

    @property
    def array(self) -> np.ndarray:
        """Control points as a (4, 3) float64 array."""
        return np.asarray(self.ctrl, dtype=np.float64)

    @property
    def duration_s(self) -> float:
        """t3 − t0."""
        return self.ctrl[3][2] - self.ctrl[0][2]

    def sample(self, n_samples: int) -> Samples:
        """Evaluate at n equally spaced τ (including both ends)."""
        return evaluate(self.array, taus(n_samples))

    def point(self, tau: float) -> tuple[float, float, float]:
        """(x, y, t) at one τ."""
        s = evaluate(self.array, np.array([float(tau)]))
        return float(s.x[0]), float(s.y[0]), float(s.t[0])

    def tau_at_time(self, t_s: float, iterations: int = 40) -> float:
        """The τ where t(τ) = t_s by bisection (t(τ) is increasing on a feasible curve)."""
        lo, hi = 0.0, 1.0
        k = coefficients(self.array)[:, 2]
        if t_s <= k[0]:
            return 0.0
        if t_s >= k.sum():
            return 1.0
        for _ in range(iterations):
            mid = 0.5 * (lo + hi)
            if k[0] + mid * (k[1] + mid * (k[2] + mid * k[3])) < t_s:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    def cost(self, n_samples: int, k1: float, k2: float) -> float:
        """k1·arc length + k2·∫|κ|dτ (eq. (9) of 000, eq. (17) of 001)."""
        s = self.sample(n_samples)
        return float(k1 * s.arc_length() + k2 * s.kappa_integral())
