"""The C planners' set-up against the Python: the control points of 000 §III.B.1 and eqs.
(7)-(11) of 001 (hostc/control_points.c), the grasp circle's end points of eq. (6)
(hostc/grasp_circle.c), the integer reference of a planned curve (hostc/path_follow.c
mg_trajectory_from_ctrl) and the plan charged in slices (hostc/anytime.c): the same inputs,
identical outputs."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mobigrasp import hostc
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.control import path_follow
from mobigrasp.host.fixedpoint import sincos_turn_q12
from mobigrasp.host.planning import control_points as cp
from mobigrasp.host.planning.anytime import PlanJob
from mobigrasp.host.planning.bezier000 import Params000, plan_000
from mobigrasp.host.planning.grasp_circle import end_points_q

FFI, C = hostc.lib()
SETTINGS = settings(max_examples=200, deadline=None)
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
