"""The C planners against the Python: the control points of 000 §III.B.1 and eqs. (7)-(11)
of 001 (hostc/control_points.c), the grasp circle's end points of eq. (6)
(hostc/grasp_circle.c), the integer reference of a planned curve (hostc/path_follow.c
mg_trajectory_from_ctrl), 000's plan whole and the planner state a C method embeds
(hostc/plan000.c, hostc/candidates.c), the plan charged in slices (hostc/anytime.c), 001's
path-update test (hostc/blocked_q.c), the sonar regions' set-up (hostc/sonar_regions.c) and
the detour's way out (hostc/escape.c): the same inputs, identical outputs."""

from __future__ import annotations

import dataclasses

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from region_ref import region_m

from mobigrasp import hostc
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.control import path_follow
from mobigrasp.host.fixedpoint import sincos_turn_q12
from mobigrasp.host.planning import control_points as cp
from mobigrasp.host.planning import escape
from mobigrasp.host.planning.anytime import PlanJob
from mobigrasp.host.planning.bezier000 import Params000, plan_000
from mobigrasp.host.planning.bezier_q import (
    POS_PER_M,
    Q16,
    REASONS,
    geo_q,
    limits_q,
    sample_ops,
)
from mobigrasp.host.planning.blocked_q import first_blocked_q, tau_at_time_q15
from mobigrasp.host.planning.candidates import batch_ops, choose_sampling
from mobigrasp.host.planning.clearance_q import clearance_words
from mobigrasp.host.planning.grasp_circle import GRID_STEPS, end_points_q, grasp_radius_um
from mobigrasp.host.planning.sonar_regions import (
    REGION_SETUP_OPS,
    InfeasibleRegion,
    SonarConfig,
    infeasible_regions_q,
    sonar_q,
)
from mobigrasp.host.task.method000 import plan_follower

FFI, C = hostc.lib()
SETTINGS = examples(200)
POS = st.integers(-(1 << 20), 1 << 20)  # 1/16 mm, ±65 m
VEC = st.integers(-40_000, 40_000)


@SETTINGS
@given(VEC, VEC)
def test_unit_vector(dx, dy):
    out = FFI.new("int32_t[2]")
    ok = C.mg_unit_q14(dx, dy, out)
    py = cp.unit_q14(dx, dy)
    assert (py is None) == (ok == 0)
    if py is not None:
        assert tuple(out) == py


@SETTINGS
@given(st.tuples(VEC, VEC), st.one_of(st.none(), st.integers(-7000, 7000)),
       st.tuples(st.integers(-16384, 16384), st.integers(-16384, 16384)),
       st.integers(0, 2000))
def test_start_direction(vel, heading, fallback, moving):
    out = FFI.new("int32_t[2]")
    C.mg_start_direction_q(vel, heading is not None, heading or 0, fallback, moving, out)
    assert tuple(out) == cp.start_direction_q(vel, heading, fallback, moving)


@SETTINGS
@given(st.integers(-5, 1 << 21), st.integers(-5, 1000), st.integers(-5, 2000))
def test_plan_numbers(dist, v0, t_s):
    out = FFI.new("mg_plan_numbers_t *")
    rc = C.mg_plan_numbers(dist, v0, t_s, out)
    if dist < 0 or v0 <= 0 or t_s <= 0:
        assert rc == -1
        return
    assert rc == 0
    assert (out.t3, out.n_i, out.dd_e, out.dd_s, out.dt_e, out.dt_s) == cp.plan_numbers(dist, v0,
                                                                                      t_s)


def _c_control_points(p0, d0, ends, d3, numbers, cap):
    num = FFI.new("mg_plan_numbers_t *", numbers)
    ctrl = FFI.new("int32_t[]", max(1, 12 * cap))
    n = C.mg_control_points_q(p0, d0, FFI.new("int64_t[]", [int(v) for v in ends.ravel()]),
                              FFI.new("int32_t[]", [int(v) for v in d3.ravel()]),
                              len(ends), num, ctrl, cap)
    return n, np.frombuffer(FFI.buffer(ctrl, 4 * 12 * max(0, n)), dtype=np.int32)


@SETTINGS
@given(st.tuples(POS, POS), st.tuples(st.integers(-16384, 16384), st.integers(-16384, 16384)),
       st.lists(st.tuples(POS, POS, st.integers(-16384, 16384), st.integers(-16384, 16384)),
                min_size=1, max_size=6),
       st.integers(0, 80_000), st.integers(50, 400), st.integers(100, 1000))
def test_control_points(p0, d0, ends, dist, v0, t_s):
    numbers = cp.plan_numbers(dist, v0, t_s)
    e = np.array([(x, y) for x, y, _, _ in ends], dtype=np.int64)
    d3 = np.array([(a, b) for _, _, a, b in ends], dtype=np.int64)
    py = cp.control_points_q(p0, d0, e, d3, numbers)
    n, c = _c_control_points(p0, d0, e, d3, numbers, len(py))
    assert n == len(py)
    assert np.array_equal(c.reshape(-1, 4, 3), py)
    n_short, _ = _c_control_points(p0, d0, e, d3, numbers, len(py) - 1)
    assert n_short == -1  # the caller's capacity is never overrun


@SETTINGS
@given(st.tuples(POS, POS), st.integers(-5, 20_000), st.integers(-1, 72))
def test_end_points(obj, l_e, n_e):
    ends = FFI.new("int64_t[]", max(1, 2 * n_e))
    dirs = FFI.new("int32_t[]", max(1, 2 * n_e))
    rc = C.mg_end_points_q(obj, l_e, n_e, ends, dirs)
    if n_e < 1 or l_e <= 0:
        assert rc == -1
        return
    py_ends, py_dirs = end_points_q(obj, l_e, n_e)
    assert list(ends)[:2 * n_e] == py_ends.ravel().tolist()
    assert list(dirs)[:2 * n_e] == py_dirs.ravel().tolist()


def _c_grasp_radius(lengths_um, steps):
    out = FFI.new("int64_t[2]", [-7, -7])
    rc = C.mg_grasp_radius_um(*lengths_um, steps, out)
    return None if rc != 0 else (out[0], out[1])


def test_grasp_radius_of_the_shipped_arms():
    # 001 §IV's arm at its h_e and at the shipped grasp height (80 mm), on the planner's grid
    for h_e_um in (208_000, 80_000):
        arm = (160_000, 160_000, 200_000, 108_000, h_e_um)
        assert _c_grasp_radius(arm, GRID_STEPS) == grasp_radius_um(*arm)
    assert _c_grasp_radius((160_000, 160_000, 200_000, 108_000, 700_000), GRID_STEPS) is None


@SETTINGS
@given(st.integers(-3, 40), st.lists(st.integers(0, 400_000), min_size=3, max_size=3),
       st.integers(0, 300_000), st.integers(-200_000, 900_000))
def test_grasp_radius(steps, links, h_r_um, h_e_um):
    arm = (links[0], links[1], links[2], h_r_um, h_e_um)
    c = _c_grasp_radius(arm, steps)
    if steps < 1 or links[0] == 0:
        assert c is None
        return
    assert c == grasp_radius_um(*arm, steps=steps)


def _c_reference(ctrl_q, n):
    out = FFI.new("mg_trajectory_t *")
    rc = C.mg_trajectory_from_ctrl([int(v) for v in np.asarray(ctrl_q).ravel()], n, out)
    if rc != 0:
        assert out.n == 0
        return None
    return list(zip(*(list(getattr(out, f))[:n] for f in (
        "t_us", "x_um", "y_um", "heading_mrad", "v_mm_s", "w_mrad_s")), strict=True))


@SETTINGS
@given(st.lists(st.integers(-(1 << 21) - 2, (1 << 21) + 2), min_size=12, max_size=12),
       st.integers(0, 300))
def test_reference_of_any_curve(ctrl, n):
    """Any control points (outside the range too), any sample count: the same table or the
    same refusal."""
    py = path_follow.reference_q(ctrl, n)
    assert _c_reference(ctrl, n) == py


@SETTINGS
@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(-0.3, 0.3), st.floats(-0.3, 0.3),
       st.floats(-3.2, 3.2), st.integers(2, 256))
def test_reference_of_planned_curves(ox, oy, vx, vy, heading, n):
    """000's best curves (increasing time, in range): the table the follower gets."""
    plan = plan_000((0.0, 0.0), (vx, vy), (ox, oy), Params000(), heading_rad=heading)
    if plan.best is None:
        return
    ctrl_q = np.rint(np.asarray(plan.best.ctrl) * 16000).astype(np.int64)
    py = path_follow.reference_q(ctrl_q, n)
    assert py is not None
    assert _c_reference(ctrl_q, n) == py
    traj = path_follow.Trajectory.from_curve(plan.best, n)
    assert hostc.ops_tuple(C.mg_trajectory_ops(n)) == traj.ops.as_tuple()


@SETTINGS
@given(st.integers(-2000, 2000), st.integers(1, 2000))
def test_sin_and_cos_of_a_fraction_of_a_turn(num, den):
    s, c = FFI.new("int32_t *"), FFI.new("int32_t *")
    C.mg_sincos_turn_q12(num, den, s, c)
    assert (s[0], c[0]) == sincos_turn_q12(num, den)
    if (4 * num) % den == 0:  # the quarter turns are exact
        assert {abs(s[0]), abs(c[0])} == {0, 4096}


@SETTINGS
@given(st.integers(0, 200_000_000), st.integers(-3, 20_000), st.integers(0, 40))
def test_plan_job_in_slices(cycles, slice_us, steps):
    ops = OpCounts(alu=cycles)
    job = FFI.new("mg_plan_job_t *")
    rc = C.mg_plan_job_start(job, FFI.new("mg_ops_t *", ops.as_tuple()), slice_us)
    if slice_us <= 0:
        assert rc == -1
        return
    py = PlanJob.start(None, None, ops, slice_us)
    for _ in range(steps):
        assert (C.mg_plan_job_done(job) != 0) == py.done
        assert C.mg_plan_job_slices(job) == py.slices()
        assert hostc.ops_tuple(C.mg_plan_job_step(job)) == py.step().as_tuple()
    assert job.remaining_us == py.remaining_us


def _params000_c(p: Params000):
    """Params000 in the C's integers (plan000.h), as plan_000 rounds them."""
    lim = limits_q(p.v_max, p.a_max, p.r_min, False)
    return FFI.new("mg_params000_t *", {
        "t_s_ms": round(p.t_s * 1000), "v0_mm_s": round(p.v0 * 1000),
        "standoff_q4": round(p.standoff_m * POS_PER_M),
        "moving_q4": round(p.moving_speed_mps * POS_PER_M), "n_samples_min": p.n_samples_min,
        "n_samples_max": p.n_samples_max, "budget_us": p.budget_us,
        "k1_q16": round(p.k1 * Q16), "k2_q16": round(p.k2 * Q16),
        "lim": [int(v) for v in lim]})


@examples(120)
@given(st.tuples(st.integers(-64_000, 64_000), st.integers(-64_000, 64_000)),
       st.tuples(st.integers(-128_000, 128_000), st.integers(-128_000, 128_000)),
       st.tuples(st.integers(-5000, 5000), st.integers(-5000, 5000)),
       st.one_of(st.none(), st.integers(-3142, 3142)),
       st.sampled_from([Params000(), Params000(v_max=0.1), Params000(r_min=2.0),
                        Params000(t_s=0.1, n_samples_max=24), Params000(standoff_m=0.0)]))
def test_plan_000_whole(start, target, vel, heading, params):
    """plan_000 and mg_plan000 from the same integers: the same candidates and reasons, the
    same sampling, the same best curve and cost, the same modelled ARM9 cost."""
    m = 1 / POS_PER_M
    py = plan_000((start[0] * m, start[1] * m), (vel[0] * m, vel[1] * m),
                  (target[0] * m, target[1] * m), params,
                  heading_rad=None if heading is None else heading / 1000)
    out = FFI.new("mg_plan000_t *")
    C.mg_plan000(_params000_c(params), start, vel, heading is not None, heading or 0, target,
                 out)
    assert hostc.ops_tuple(out.ops) == py.ops.as_tuple()
    if "standoff" in py.reason:
        assert out.status == 1
        return
    assert (out.n_samples, out.stride, out.n_cand) == (py.n_samples, py.stride,
                                                       len(py.candidates))
    reasons = [0] * 9
    for r in py.candidates.reasons:
        reasons[REASONS.index(r)] += 1
    assert list(out.reasons) == reasons
    ctrl = FFI.new("int32_t[12]")
    for i in range(0, out.n_cand, max(1, out.n_cand // 7)):
        C.mg_plan000_ctrl(out, i, ctrl)
        assert list(ctrl) == np.rint(py.candidates.ctrl[i] * POS_PER_M).astype(int).ravel().tolist()
    if py.best is None:
        assert out.status == 2 and out.best == -1
        return
    assert out.status == 0
    assert py.best_candidate.u == 1 + out.best * out.stride
    assert list(out.best_ctrl) == np.rint(np.asarray(py.best.ctrl) * POS_PER_M).astype(
        int).ravel().tolist()
    assert out.best_cost_q16 / Q16 == py.best_candidate.cost


@SETTINGS
@given(st.integers(0, 5000), st.integers(1, 40_000), st.integers(-20_000, 200_000),
       st.integers(2, 64), st.integers(2, 96))
def test_sampling_of_a_candidate_set(n_cand, per_sample, budget_us, n_min, extra):
    n, stride = FFI.new("int32_t *"), FFI.new("int32_t *")
    C.mg_choose_sampling(n_cand, per_sample, budget_us, n_min, n_min + extra, n, stride)
    assert (n[0], stride[0]) == choose_sampling(n_cand, per_sample, budget_us, n_min,
                                                n_min + extra)


@SETTINGS
@given(st.integers(0, 200), st.integers(2, 100), st.booleans(), st.booleans(),
       st.integers(0, 12), st.sampled_from([3, 6]))
def test_curve_ops(first, n, positions, circle, regions, divs):
    kw = {"positions": positions, "grasp_circle": circle, "regions": regions,
          "divs_per_sample": divs}
    assert hostc.ops_tuple(C.mg_curve_ops(min(first, n), n, positions, circle, regions, divs)) \
        == batch_ops(np.array([min(first, n)]), n, **kw).as_tuple()
    assert hostc.ops_tuple(C.mg_sample_ops(n, positions, circle, regions, divs)) \
        == sample_ops(n, **kw).as_tuple()


REGIONS = st.builds(
    lambda ox, oy, lo, width, eta, arc: region_m(ox, oy, lo, lo + width, eta, 0.2, arc),
    st.floats(-3, 3), st.floats(-3, 3), st.floats(-4, 4), st.floats(0.1, 1.0),
    st.floats(0.1, 2.4), st.booleans())


@SETTINGS
@given(st.lists(st.integers(-48_000, 48_000), min_size=8, max_size=8),
       st.integers(16_000, 500_000), st.integers(-20_000, 520_000),
       st.lists(REGIONS, max_size=5), st.integers(2, 64))
def test_path_update_check(xy, dur, t_q4, regions, m):
    """001's path-update test: the same present τ, the same first blocked sample (or none),
    the same modelled cost."""
    ctrl = [xy[0], xy[1], 0, xy[2], xy[3], dur // 3, xy[4], xy[5], 2 * dur // 3, xy[6], xy[7],
            dur]
    ctrl_q = np.array(ctrl, dtype=np.int64).reshape(4, 3)
    tau0 = tau_at_time_q15(ctrl_q, t_q4)
    assert C.mg_tau_at_time_q15(ctrl, t_q4) == tau0
    geo = geo_q((0.0, 0.0), 0.0, regions)
    where, ops = first_blocked_q(ctrl_q, tau0, m, geo, len(regions))
    c_where, c_ops = FFI.new("int64_t[2]"), FFI.new("mg_ops_t *")
    hit = C.mg_first_blocked_q(ctrl, tau0, m, FFI.new("int64_t[]", [int(v) for v in geo]),
                               len(regions), c_where, c_ops)
    assert (tuple(c_where) if hit else None) == where
    assert hostc.ops_tuple(c_ops[0]) == ops.as_tuple()


INT_REGIONS = st.builds(
    InfeasibleRegion, POS, POS, st.integers(-40_000_000, 40_000_000),
    st.integers(-40_000_000, 40_000_000), st.integers(0, 1 << 19), st.integers(0, 1 << 14),
    st.booleans())


def _region_c(reg: InfeasibleRegion):
    return FFI.new("mg_region_t *", [reg.ox_q4, reg.oy_q4, reg.lo_urad, reg.hi_urad, reg.eta_q4,
                                     reg.r_r_q4, int(reg.arc_bound)])


@SETTINGS
@given(INT_REGIONS)
def test_region_words(reg):
    """A region's words in integers (eq. (16)'s apex, bisector, half-angle, band, arc bound;
    the echo arc's ends and middle): identical, also for empty and reversed wedges."""
    w = FFI.new("mg_region_words_t *")
    C.mg_region_words(_region_c(reg), w)
    py = reg.words
    assert [getattr(w[0], f) for f in py.__dataclass_fields__] == list(dataclasses.astuple(py))
    geo, clear = FFI.new("int64_t[12]"), FFI.new("int64_t[11]")
    C.mg_region_geo(_region_c(reg), geo)
    C.mg_region_clear(_region_c(reg), clear)
    assert list(geo) == [int(v) for v in geo_q((0.0, 0.0), 0.0, [reg])[3:]]
    assert list(clear) == [int(v) for v in clearance_words([reg])[0]]
    assert hostc.ops_tuple(C.mg_region_setup_ops()) == REGION_SETUP_OPS.as_tuple()


@SETTINGS
@given(st.integers(2, 16), st.floats(0.05, 3.1), st.floats(0.3, 6.0), st.floats(0.0, 0.6),
       st.one_of(st.none(), st.floats(0.0, 0.3)), st.floats(0.0, 0.3), st.booleans(),
       st.lists(st.integers(-2, 70_000), min_size=16, max_size=16), POS, POS,
       st.integers(-20_000_000, 20_000_000))
def test_sonar_regions(k_s, a_g, d_e, r_r, tol, offset, arc, sonar, px, py, heading_urad):
    """Eq. (15)'s sub-regions and eq. (16)'s regions of a reading: the same regions (negative
    readings counted and taken as no echo)."""
    cfg = SonarConfig(k_s, a_g, d_e, r_r, tol, offset, arc)
    q = sonar_q(cfg)
    c_cfg = FFI.new("mg_sonar_cfg_t *", [q.k_s, q.a_g_urad, q.d_e_q4, q.r_r_q4, q.tol_q4,
                                         q.offset_q4, int(q.arc_bound), q.cot_half_q12])
    out, dropped = FFI.new("mg_region_t[31]"), FFI.new("int32_t *")
    n = C.mg_sonar_regions(c_cfg, px, py, heading_urad, sonar[:k_s], out, dropped)
    scan = infeasible_regions_q(cfg, px, py, heading_urad, sonar[:k_s])
    assert dropped[0] == scan.dropped
    got = [InfeasibleRegion(r.ox_q4, r.oy_q4, r.lo_urad, r.hi_urad, r.eta_q4, r.r_r_q4,
                            bool(r.arc_bound)) for r in out[0:n]]
    assert got == scan.regions


def _words_c(regions):
    """The regions' words one by one: bezier.h's geo and clearance.c's, as escape._Words."""
    geo = [int(v) for r in regions for v in geo_q((0.0, 0.0), 0.0, [r])]
    clear = [int(v) for v in clearance_words(regions).ravel()]
    return FFI.new("int64_t[]", geo or [0]), FFI.new("int64_t[]", clear or [0])


def _less_setup(ops, regions):
    """Python's counts less the regions' set-up (escape.REGION_WORDS_OPS), which the C is
    given done."""
    setup = escape.REGION_WORDS_OPS.scaled(len(regions)).as_tuple()
    return tuple(a - b for a, b in zip(ops.as_tuple(), setup, strict=True))


NEAR_REGIONS = st.builds(
    lambda ox, oy, lo, width, eta, arc: region_m(ox, oy, lo, lo + width, eta, 0.2, arc),
    st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), st.floats(-4, 4), st.floats(0.1, 1.0),
    st.floats(0.1, 1.5), st.booleans())


@SETTINGS
@given(st.lists(NEAR_REGIONS, max_size=4), st.tuples(st.integers(-8000, 8000),
                                                     st.integers(-8000, 8000)),
       st.integers(-4000, 4000), st.integers(-100, 32_000), st.integers(1, 24), st.booleans())
def test_segment_test(regions, pos, heading, length, samples, leave_ok):
    """The detour's straight-segment test: the same verdict, the same modelled cost."""
    g, c = _words_c(regions)
    ops = FFI.new("mg_ops_t *")
    m = 1 / POS_PER_M
    clear = C.mg_segment_clear_q(g, c, len(regions), pos[0], pos[1], heading, length, samples,
                                 leave_ok, ops)
    py, py_ops = escape.segment_clear(regions, (pos[0] * m, pos[1] * m), heading / 1000,
                                      length * m, samples, leave_ok)
    assert bool(clear) == py
    assert hostc.ops_tuple(ops[0]) == _less_setup(py_ops, regions if length > 0 else [])


@SETTINGS
@given(st.lists(NEAR_REGIONS, max_size=4), st.tuples(st.integers(-8000, 8000),
                                                     st.integers(-8000, 8000)),
       st.integers(-4_000_000, 4_000_000), st.integers(-4_000_000, 4_000_000),
       st.integers(50_000, 700_000), st.integers(0, 12), st.integers(1600, 24_000),
       st.integers(1, 20), st.sampled_from([-1, 0, 1]))
def test_escape_heading(regions, pos, h, goal, step, n_side, length, samples, side):
    """The detour's heading: the same heading (or none) and the same modelled cost (the C's
    without the regions' float set-up)."""
    g, c = _words_c(regions)
    ops, out = FFI.new("mg_ops_t *"), FFI.new("int64_t *")
    found = C.mg_escape_heading_q(g, c, len(regions), pos[0], pos[1], h, goal, step, n_side,
                                  length, samples, side, out, ops)
    m = 1 / POS_PER_M
    py, py_ops = escape.escape_heading(regions, (pos[0] * m, pos[1] * m), h / 1e6, goal / 1e6,
                                       length * m, step_rad=step / 1e6,
                                       span_rad=n_side * step / 1e6, samples=samples, side=side)
    assert (round(py * 1e6) if py is not None else None) == (out[0] if found else None)
    assert hostc.ops_tuple(ops[0]) == _less_setup(py_ops, regions)


@examples(60)
@given(st.integers(-3000, 3000), st.integers(-3000, 3000), st.integers(-3142, 3141),
       st.integers(-300, 300), st.tuples(st.integers(-4000, 4000), st.integers(-4000, 4000)))
def test_planner_state_of_000(x_mm, y_mm, heading, v_mmps, obj):
    """The task's call (method000.plan_follower, approach.py's PlanJob) and the planner state
    of the C method: the same reference table, the same cost, the same slices."""
    follower, ops, _ = plan_follower(0, x_mm, y_mm, heading, v_mmps, obj)
    pl = FFI.new("mg_planner000_t *")
    C.mg_planner000_start(pl, _params000_c(Params000()), x_mm, y_mm, heading, v_mmps, obj)
    assert hostc.ops_tuple(pl.ops) == ops.as_tuple()
    assert (pl.traj.n > 0) == (follower is not None)
    if follower is not None:
        tr = follower.traj
        for name in ("t_us", "x_um", "y_um", "heading_mrad", "v_mm_s", "w_mrad_s"):
            assert list(getattr(pl.traj, name))[:pl.traj.n] == list(getattr(tr, name))
    job = PlanJob.start(None, None, ops)
    done = FFI.new("int *")
    while True:
        assert hostc.ops_tuple(C.mg_planner000_step(pl, done)) == job.step().as_tuple()
        assert bool(done[0]) == job.done
        if job.done:
            break
