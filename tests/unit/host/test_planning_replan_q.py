"""The path-update test of 001 §III.E in fixed point (host/planning/blocked_q.py, the
Replanner's memory test) against float references: blocked is blocked with R_r grown by 3 mm,
clear is clear with R_r shrunk by 3 mm; the present τ within 1/4 ms."""

import math

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st
from property_examples import examples
from region_ref import Ref, grown_m, region_m

from mobigrasp.host.planning.bezier import Curve, evaluate
from mobigrasp.host.planning.bezier_q import POS_PER_M, TIME_PER_S, geo_q, quantize_ctrl
from mobigrasp.host.planning.blocked_q import first_blocked_q, tau_at_time_q15
from mobigrasp.host.planning.replan import Replanner

TOL_M = 0.003


def blocked_float(curve: Curve, tau0: float, m: int, regions) -> bool:
    tau = np.linspace(tau0, 1.0, m)[1:]
    s = evaluate(curve.array, tau)
    return any(bool(Ref(r).contains(s.x, s.y).any()) for r in regions)


def forget_float(memory, position_xy_m, heading_rad, d_e_m, a_g_rad) -> list[bool]:
    """True for each region the sonars see again (the float form of Replanner.forget_seen)."""
    px, py = position_xy_m
    span = math.pi / 2 + a_g_rad / 2
    out = []
    for reg in map(Ref, memory):
        mid = reg.mid
        ax = reg.ox + reg.eta_m * math.cos(mid) - px
        ay = reg.oy + reg.eta_m * math.sin(mid) - py
        rel = (math.atan2(ay, ax) - heading_rad + math.pi) % (2 * math.pi) - math.pi
        out.append(math.hypot(ax, ay) < d_e_m and abs(rel) <= span)
    return out


curve = st.builds(
    lambda x0, y0, dx1, dy1, dx2, dy2, x3, y3, dur: Curve((
        (x0, y0, 0.0), (x0 + dx1, y0 + dy1, dur / 3), (x3 - dx2, y3 - dy2, 2 * dur / 3),
        (x3, y3, dur))),
    st.floats(-2, 2), st.floats(-2, 2), st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1),
    st.floats(-1, 1), st.floats(-3, 3), st.floats(-3, 3), st.floats(5, 30))
region = st.builds(
    lambda ox, oy, lo, width, eta: region_m(ox, oy, lo, lo + width, eta, 0.2),
    st.floats(-3, 3), st.floats(-3, 3), st.floats(-4, 4), st.floats(0.1, 1.0),
    st.floats(0.3, 2.4))


@examples(150)
@given(curve, st.floats(0, 1), st.lists(region, min_size=1, max_size=4),
       st.integers(3, 40))
def test_blocked_test_within_3mm_of_float(c, frac, regs, m):
    ctrl_q = quantize_ctrl(c.array)
    dur = float(ctrl_q[3, 2] - ctrl_q[0, 2]) / TIME_PER_S
    t_q4 = int(ctrl_q[0, 2]) + round(frac * dur * TIME_PER_S)
    tau0 = tau_at_time_q15(ctrl_q, t_q4)
    cq = Curve.from_array(ctrl_q / POS_PER_M)  # POS_PER_M == TIME_PER_S
    # the present τ: t(τ) of the same (quantized) curve in float reaches the present time
    # there, and not one Q15 step before, within 4 counts (1/4 ms: Horner's floor shifts)
    t_at = evaluate(cq.array, np.array([tau0, max(tau0 - 1, 0)]) / 2**15).t * TIME_PER_S
    assert t_at[0] >= t_q4 - 4 and (tau0 == 0 or t_at[1] < t_q4 + 4)
    where, ops = first_blocked_q(ctrl_q, tau0, m, geo_q((0.0, 0.0), 0.0, regs), len(regs))
    assert ops.time_us() > 0
    grown = [grown_m(r, TOL_M) for r in regs]
    shrunk = [grown_m(r, -TOL_M) for r in regs]
    if where is not None:
        assert blocked_float(cq, tau0 / 2**15, m, grown)
        wx, wy = where[0] / POS_PER_M, where[1] / POS_PER_M
        assert any(bool(Ref(r).contains(wx, wy)) for r in grown)
    else:
        assert not blocked_float(cq, tau0 / 2**15, m, shrunk)


def test_present_tau_before_and_after_the_curve():
    c = Curve(((0, 0, 1.0), (1, 0, 2.0), (2, 0, 3.0), (3, 0, 4.0)))
    q = quantize_ctrl(c.array)
    assert tau_at_time_q15(q, 0) == 0
    assert tau_at_time_q15(q, 5 * TIME_PER_S) == 2**15
    assert tau_at_time_q15(q, round(2.5 * TIME_PER_S)) == 2**14  # t linear in τ here


@examples(200)
@given(st.lists(region, min_size=1, max_size=6), st.floats(-2, 2), st.floats(-2, 2),
       st.floats(-math.pi, math.pi))
def test_forget_seen_matches_float_away_from_the_edges(regs, px, py, heading):
    rp = Replanner((4.0, 0.0))
    cfg = rp.params.sonar
    span = math.pi / 2 + cfg.a_g_rad / 2
    for reg in map(Ref, regs):  # decisions within 1 mm or 2 mrad of an edge may go either way
        mid = reg.mid
        ax = reg.ox + reg.eta_m * math.cos(mid) - px
        ay = reg.oy + reg.eta_m * math.sin(mid) - py
        rel = (math.atan2(ay, ax) - heading + math.pi) % (2 * math.pi) - math.pi
        assume(abs(math.hypot(ax, ay) - cfg.d_e_m) > 1e-3 and abs(abs(rel) - span) > 2e-3)
    rp.memory.extend(regs)
    seen = forget_float(regs, (px, py), heading, cfg.d_e_m, cfg.a_g_rad)
    dropped = rp.forget_seen((px, py), heading)
    assert dropped == sum(seen)
    assert list(rp.memory) == [r for r, s in zip(regs, seen, strict=True) if not s]
