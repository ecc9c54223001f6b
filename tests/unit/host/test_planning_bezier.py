"""Cubic Bezier with time (eqs. (4)-(7) of 000): each quantity against an independent reference."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host.planning.bezier import Curve, coefficients, evaluate, taus
from mobigrasp.host.planning.bezier_q import sample_ops


def bernstein(ctrl, tau):
    """Eq. (5) of 000 directly: sum of C(3,i)(1-τ)^(3-i) τ^i q_i."""
    ctrl = np.asarray(ctrl, dtype=float)
    return sum(math.comb(3, i) * (1 - tau) ** (3 - i) * tau**i * ctrl[i] for i in range(4))


def random_ctrl(rng):
    xy = rng.uniform(-2, 2, size=(4, 2))
    t = np.cumsum(rng.uniform(0.5, 3.0, size=4)) - 0.5
    return np.column_stack([xy, t])


def test_power_form_equals_bernstein_form():
    rng = np.random.default_rng(1)
    for _ in range(20):
        ctrl = random_ctrl(rng)
        k = coefficients(ctrl)
        for tau in rng.uniform(0, 1, 5):
            power = k[0] + k[1] * tau + k[2] * tau**2 + k[3] * tau**3  # eq. (6)
            assert np.allclose(power, bernstein(ctrl, tau), atol=1e-12)


def test_straight_uniform_line_hand_worked():
    # x = 3τ, y = 0, t = 3τ: speed 1 m/s, no curvature, no acceleration, length 3 m.
    c = Curve(((0, 0, 0), (1, 0, 1), (2, 0, 2), (3, 0, 3)))
    s = c.sample(11)
    assert np.allclose(s.speed, 1.0)
    assert np.allclose(s.kappa, 0.0)
    assert np.allclose(s.accel_tangential, 0.0)
    assert s.arc_length() == pytest.approx(3.0)
    assert s.kappa_integral() == pytest.approx(0.0)
    assert c.duration_s == 3
    assert c.tau_at_time(1.5) == pytest.approx(0.5, abs=1e-9)


def test_known_coefficients():
    # P0=(0,0,0), P1=(1,0,1), P2=(1,1,2), P3=(0,1,3):
    # a = (0, 3, 0, -2)·...: x(τ) = 3τ - 3τ², y(τ) = 3τ² - 2τ³, t(τ) = 3τ.
    k = coefficients(np.array([[0, 0, 0], [1, 0, 1], [1, 1, 2], [0, 1, 3]], float))
    assert np.allclose(k[:, 0], [0, 3, -3, 0])
    assert np.allclose(k[:, 1], [0, 0, 3, -2])
    assert np.allclose(k[:, 2], [0, 3, 0, 0])


def finite_difference_reference(ctrl, tau, h=1e-6):
    """Speed, tangential acceleration and curvature from positions only (central differences)."""
    def p(t):
        return bernstein(ctrl, t)

    d1 = (p(tau + h) - p(tau - h)) / (2 * h)
    d2 = (p(tau + h) - 2 * p(tau) + p(tau - h)) / h**2
    speed = math.hypot(d1[0], d1[1]) / d1[2]
    kappa = (d1[0] * d2[1] - d2[0] * d1[1]) / math.hypot(d1[0], d1[1]) ** 3

    def v(t):
        d = (p(t + h) - p(t - h)) / (2 * h)
        return math.hypot(d[0], d[1]) / d[2]

    hh = 1e-4
    dv_dtau = (v(tau + hh) - v(tau - hh)) / (2 * hh)
    return speed, dv_dtau / d1[2], kappa


def test_speed_accel_curvature_against_finite_differences():
    rng = np.random.default_rng(7)
    for _ in range(15):
        ctrl = random_ctrl(rng)
        tau = rng.uniform(0.1, 0.9, 4)
        s = evaluate(ctrl, tau)
        for j, t in enumerate(tau):
            v, a_t, kappa = finite_difference_reference(ctrl, t)
            assert s.speed[j] == pytest.approx(v, rel=1e-5, abs=1e-7)
            assert s.accel_tangential[j] == pytest.approx(a_t, rel=1e-3, abs=1e-5)
            assert s.kappa[j] == pytest.approx(kappa, rel=2e-3, abs=1e-3)


def test_eq8_yaw_rate_equals_v_kappa():
    """w_w = a_i sin(Δθ)/v of eq. (8) of 000 (acceleration vector of eq. (7)) equals v·κ."""
    rng = np.random.default_rng(3)
    ctrl = random_ctrl(rng)
    s = evaluate(ctrl, np.linspace(0.05, 0.95, 9))
    vx, vy = s.x_tau / s.t_tau, s.y_tau / s.t_tau
    # a_tx = (dv_x/dτ)/t_τ with dv_x/dτ = (x_2τ t_τ - x_τ t_2τ)/t_τ²
    ax = (s.x_2tau * s.t_tau - s.x_tau * s.t_2tau) / s.t_tau**3
    ay = (s.y_2tau * s.t_tau - s.y_tau * s.t_2tau) / s.t_tau**3
    a = np.hypot(ax, ay)
    dtheta = np.arctan2(ay, ax) - np.arctan2(vy, vx)
    w = a * np.sin(dtheta) / np.hypot(vx, vy)
    assert np.allclose(w, s.omega, rtol=1e-9, atol=1e-12)
    # tangential part of the same vector is dv/dt
    assert np.allclose(a * np.cos(dtheta), s.accel_tangential, rtol=1e-9, atol=1e-12)
    assert np.allclose(s.accel_normal, np.abs(a * np.sin(dtheta)), rtol=1e-9, atol=1e-12)


@examples(60)
@given(st.integers(0, 2**31 - 1))
def test_arc_length_matches_polyline(seed):
    ctrl = random_ctrl(np.random.default_rng(seed))
    s = Curve.from_array(ctrl).sample(801)
    poly = np.sum(np.hypot(np.diff(s.x), np.diff(s.y)))
    assert s.arc_length() == pytest.approx(poly, rel=1e-4, abs=1e-6)


def test_left_turn_has_positive_curvature():
    c = Curve(((0, 0, 0), (1, 0, 1), (1, 1, 2), (0, 1, 3)))  # counter-clockwise hook
    assert np.all(c.sample(9).kappa > 0)
    mirrored = Curve(((0, 0, 0), (1, 0, 1), (1, -1, 2), (0, -1, 3)))
    assert np.all(mirrored.sample(9).kappa < 0)


def test_cost_is_k1_length_plus_k2_kappa_integral():
    c = Curve(((0, 0, 0), (1, 0, 1), (1, 1, 2), (0, 1, 3)))
    s = c.sample(2001)
    ref_len = np.sum(np.hypot(np.diff(s.x), np.diff(s.y)))
    ref_k = np.trapezoid(np.abs(s.kappa), s.tau)
    assert c.cost(2001, 0.5, 0.5) == pytest.approx(0.5 * ref_len + 0.5 * ref_k, rel=1e-5)


def test_ops_are_linear_in_samples_and_integer_only():
    a, b = sample_ops(10), sample_ops(20)
    assert b.cycles() - a.cycles() == a.cycles() - sample_ops(0).cycles() > 0
    assert a.float_ops == a.float_divs == 0 and a.muls32 > 0
    assert sample_ops(10, regions=3).cycles() > sample_ops(10, regions=1).cycles()
    assert sample_ops(10, divs_per_sample=6).cycles() > sample_ops(10, divs_per_sample=3).cycles()


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="4 finite"):
        Curve(((0, 0, 0), (1, 0, 1), (2, 0, 2)))
    with pytest.raises(ValueError, match="4 finite"):
        Curve(((0, 0, 0), (1, 0, 1), (2, 0, float("nan")), (3, 0, 3)))
    with pytest.raises(ValueError, match="n_samples"):
        taus(1)
