"""Fuzzy approaching of 002 §3: rule table cell by cell, integer vs float reference, eq. (2)."""

import math

import numpy as np
import pytest

import mobigrasp.host.control.fuzzy as fz
from mobigrasp.host.control.fuzzy import FuzzyApproach, FuzzyController, FuzzyParams

# Table 1 of 002 typed again from the paper (rows E_c = NB..PB, columns E = NB..PB).
TABLE_1 = """
NB NB NM NM Z  PS PM
NB NM NS NS Z  PS PM
NB NM NS Z  PS PM PB
NM NS Z  Z  PS PM PB
NS NS Z  PS PS PM PB
"""
E_NAMES = ["NB", "NM", "NS", "Z", "PS", "PM", "PB"]
EC_NAMES = ["NB", "NS", "Z", "PS", "PB"]
U_CENTRE = {n: (i - 3) / 3 for i, n in enumerate(E_NAMES)}
CELLS = [(k, j, row.split()[j]) for k, row in enumerate(TABLE_1.strip().splitlines())
         for j in range(7)]


@pytest.mark.parametrize("k,j,expected", CELLS,
                         ids=[f"Ec={EC_NAMES[k]}-E={E_NAMES[j]}" for k, j, _ in CELLS])
def test_rule_table_cell(k, j, expected):
    """At the peaks of E_j and E_c,k exactly one rule fires with μ = 1: u is that rule's b_h."""
    ctl = FuzzyController()
    e_mrad = round((j - 3) / 3 * 1430)
    ec = round((k - 2) / 2 * 5000)
    u = ctl.u_mrad(e_mrad, ec)
    assert u == pytest.approx(1000 * U_CENTRE[expected], abs=1.5)
    assert fz.RULE_TABLE[k][j] == expected


def tri(x, centres):
    """Float reference: triangular memberships with feet on the neighbouring peaks."""
    width = centres[1] - centres[0]
    return np.maximum(0.0, 1.0 - np.abs(x[..., None] - np.asarray(centres)) / width)


def float_reference_u(e_rad, ec_rad_s):
    xe = np.clip(np.asarray(e_rad) / 1.43, -1, 1)
    xec = np.clip(np.asarray(ec_rad_s) / 5.0, -1, 1)
    mu_e = tri(xe, np.linspace(-1, 1, 7))
    mu_ec = tri(xec, np.linspace(-1, 1, 5))
    rules = np.array([[E_NAMES.index(s) for s in row.split()]
                      for row in TABLE_1.strip().splitlines()])
    w = np.minimum(mu_ec[..., :, None], mu_e[..., None, :])  # (.., 5, 7)
    b = (rules - 3) / 3.0
    return (w * b).sum(axis=(-1, -2)) / w.sum(axis=(-1, -2))  # eq. (1), u_th = 1


def test_integer_matches_float_reference_over_the_whole_input_grid():
    ctl = FuzzyController()
    es = np.arange(-1600, 1601, 8)  # beyond ±e_th to cover the saturation
    ecs = np.arange(-5600, 5601, 100)
    got = np.array([[ctl.u_mrad(int(e), int(ec)) for e in es] for ec in ecs])
    ref = 1000 * float_reference_u(es[None, :] / 1000.0, ecs[:, None] / 1000.0)
    err = np.abs(got - ref)
    assert err.max() <= 1.5  # mrad: rounding of the quantised inputs and of the output
    assert ctl.no_rule_fired == 0
    assert np.abs(got).max() == 1000  # saturates at u_th


def test_memberships_cover_the_universe():
    for x in range(-12288, 12289, 97):
        mus = fz.memberships(x, 7)
        assert sum(m for _, m in mus) == 4096 and 1 <= len(mus) <= 2
    for x in range(-8192, 8193, 61):
        assert sum(m for _, m in fz.memberships(x, 5)) == 4096


def test_no_rule_fired_is_defined_and_counted(monkeypatch):
    ctl = FuzzyController()
    monkeypatch.setattr(fz, "memberships", lambda x, n: [])
    assert ctl.u_mrad(500, 0) == 0
    assert ctl.no_rule_fired == 1


def test_wheel_speeds_eq2_and_sign():
    ctl = FuzzyController()
    for u in (-1000, -400, 0, 250, 1000):
        v_l, v_r = ctl.wheels_mm_s(u)
        ref_r = 2 * 150 / (2 + u / 1000)
        assert v_r == pytest.approx(ref_r, abs=0.51)
        assert v_l + v_r == 300
    v_l, v_r = ctl.wheels_mm_s(ctl.u_mrad(300, 0))  # marker to the right
    assert v_l > v_r  # turns right (clockwise)
    v_l, v_r = ctl.wheels_mm_s(ctl.u_mrad(-300, 0))  # left is negative
    assert v_l < v_r


def test_stop_threshold_and_lost_marker():
    f = FuzzyApproach()
    assert f.step(0, 100, d_pixel=45).stop is False
    cmd = f.step(50_000, 100, d_pixel=46)
    assert cmd.stop and (cmd.left_mm_s, cmd.right_mm_s) == (0, 0)
    lost = f.step(100_000, None)
    assert not lost.stop and (lost.left_mm_s, lost.right_mm_s) == (0, 0)
    with pytest.raises(ValueError, match="thresholds"):
        FuzzyParams(e_th_mrad=0)


def test_error_rate_is_from_successive_samples():
    f = FuzzyApproach()
    f.step(0, 0)
    a = f.step(100_000, 100)  # e_c = 1000 mrad/s, PS-ish: more right turn than e alone
    g = FuzzyApproach()
    b = g.step(0, 100)  # first sample: e_c = 0
    assert a.u_mrad != b.u_mrad


def approach(seed):
    """Kinematic unicycle driven by the fuzzy loop toward a marker at the origin (20 Hz)."""
    rng = np.random.default_rng(seed)
    r = rng.uniform(1.0, 3.0)
    ang = rng.uniform(-math.pi, math.pi)
    x, y = r * math.cos(ang), r * math.sin(ang)
    th = ang + math.pi + rng.uniform(-0.8, 0.8)
    f = FuzzyApproach()
    dt = 0.05
    for step in range(2400):
        dist = math.hypot(x, y)
        d_pixel = int(14.5 * 350 / (dist * 1000))  # ring spacing D f / distance
        bearing = math.atan2(-y, -x) - th
        bearing = (bearing + math.pi) % (2 * math.pi) - math.pi
        e_mrad = round(-bearing * 1000)  # positive to the right
        cmd = f.step(step * 50_000, e_mrad, d_pixel)
        if cmd.stop:
            return dist, abs(bearing)
        vl, vr = cmd.left_mm_s / 1000, cmd.right_mm_s / 1000
        v, w = (vl + vr) / 2, (vr - vl) / 0.3
        x += v * dt * math.cos(th)
        y += v * dt * math.sin(th)
        th += w * dt
    return None, None


def test_closed_loop_reaches_the_marker_from_seeded_starts():
    """Stops by the T_d rule within reach (D f / T_d = 113 mm) with the marker inside the
    waist range (|bearing| < 0.8 rad, the waist turns ±1.4 rad) in >= 95 of 100 starts."""
    results = [approach(s) for s in range(100)]
    ok = [d is not None and d < 0.12 and b < 0.8 for d, b in results]
    assert sum(ok) >= 95
    assert all(d is None or d > 0.09 for d, _ in results)  # not before the threshold
