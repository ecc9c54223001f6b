"""The C host's controllers against the Python ones: path following (eq. (8) of 000 and
Kanayama's tracking law, hostc/path_follow.c) and the fuzzy approach of 002 (hostc/fuzzy.c)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.control import fuzzy, path_follow
from mobigrasp.host.odometry import Pose

FFI, C = hostc.lib()
SETTINGS = examples(150)


@st.composite
def trajectories(draw):
    """An integer reference table as Trajectory.from_curve makes: increasing times from 0."""
    n = draw(st.integers(2, 40))
    gaps = draw(st.lists(st.integers(0, 200_000), min_size=n - 1, max_size=n - 1))
    t = [0]
    for g in gaps:
        t.append(t[-1] + g)
    col = st.lists(st.integers(-5_000_000, 5_000_000), min_size=n, max_size=n)
    ang = st.lists(st.integers(-3142, 3141), min_size=n, max_size=n)
    speed = st.lists(st.integers(-1200, 1200), min_size=n, max_size=n)
    return path_follow.Trajectory(tuple(t), tuple(draw(col)), tuple(draw(col)),
                                  tuple(draw(ang)), tuple(draw(speed)),
                                  tuple(draw(speed)), OpCounts())


def _c_traj(tr):
    c = FFI.new("mg_trajectory_t *")
    c.n = len(tr.t_us)
    for name in ("t_us", "x_um", "y_um", "heading_mrad", "v_mm_s", "w_mrad_s"):
        getattr(c, name)[0:c.n] = getattr(tr, name)
    return c


@SETTINGS
@given(trajectories(), st.lists(st.tuples(st.integers(-100_000, 8_000_000),
                                          st.integers(-50, 50)), min_size=1, max_size=30))
def test_reference_lookup(tr, queries):
    c = _c_traj(tr)
    for t_us, hint in queries:
        r = C.mg_trajectory_at(c, t_us, hint)
        assert (r.x_um, r.y_um, r.heading_mrad, r.v_mm_s, r.w_mrad_s, r.index) == tr.at(t_us,
                                                                                          hint)


@SETTINGS
@given(st.integers(-3000, 3000), st.integers(-20_000, 20_000), st.integers(-100, 1500))
def test_wheel_speeds_eq8(v, w, limit):
    left, right = FFI.new("int32_t *"), FFI.new("int32_t *")
    C.mg_wheel_speeds(v, w, limit, left, right)
    assert (left[0], right[0]) == path_follow.wheel_speeds(v, w, limit)


POSES = st.builds(Pose, st.integers(-6_000_000, 6_000_000), st.integers(-6_000_000, 6_000_000),
                  st.integers(-3142, 3141), st.just(0), st.just(0))


@SETTINGS
@given(trajectories(), st.integers(-1_000_000, 1_000_000), st.integers(0, 1000),
       st.builds(path_follow.FollowGains, st.integers(0, 20_000), st.integers(0, 64),
                 st.integers(0, 64)), st.integers(0, 100), st.integers(0, 5_000_000),
       st.lists(st.tuples(st.integers(0, 400_000), POSES), min_size=10, max_size=40))
def test_follower_steps(tr, start_us, v_limit, gains, tol, overtime, steps):
    """A sequence of steps at increasing times from arbitrary poses: the same commands, the
    same segment hint carried from step to step."""
    py = path_follow.PathFollower(tr, start_us, v_limit, gains, tol, overtime)
    c_tr = _c_traj(tr)
    c = FFI.new("mg_path_follower_t *")
    C.mg_path_follower_init(c, c_tr, start_us, v_limit,
                            FFI.new("mg_follow_gains_t *", (gains.k_x_q12, gains.k_y_per_m2,
                                                            gains.k_theta_per_m)),
                            tol, overtime)
    t_us = start_us - 50_000
    for dt, pose in steps:
        t_us += dt
        cp = FFI.new("mg_pose_t *", (pose.x_um, pose.y_um, pose.heading_mrad, 0, 0))
        got = C.mg_path_follower_step(c, t_us, cp)
        e = py.step(t_us, pose)
        assert (got.left_mm_s, got.right_mm_s, bool(got.done), got.error_mm) == (
            e.left_mm_s, e.right_mm_s, e.done, e.error_mm)
    assert c.steps == py.steps
    assert hostc.ops_tuple(C.mg_path_follow_step_ops()) == path_follow.STEP_OPS.as_tuple()


FUZZY_PARAMS = st.just(fuzzy.FuzzyParams()) | st.builds(
    fuzzy.FuzzyParams, st.integers(1, 3000), st.integers(1, 9000), st.integers(1, 1000),
    st.integers(0, 400), st.integers(0, 4096), st.integers(0, 80))


def _c_params(p):
    return FFI.new("mg_fuzzy_params_t *", (p.e_th_mrad, p.e_cth_mrad_s, p.u_th_mrad,
                                           p.v_avg_mm_s, p.k_uc_q12, p.t_d_px))


@SETTINGS
@given(FUZZY_PARAMS, st.integers(-4000, 4000), st.integers(-(1 << 40), 1 << 40),
       st.integers(-1000, 1000))
def test_fuzzy_inference(params, e, ec, u):
    py = fuzzy.FuzzyController(params)
    c = FFI.new("mg_fuzzy_controller_t *")
    C.mg_fuzzy_controller_init(c, _c_params(params))
    x_e, x_ec = FFI.new("int32_t *"), FFI.new("int32_t *")
    C.mg_fuzzy_quantise(c, e, ec, x_e, x_ec)
    assert (x_e[0], x_ec[0]) == py.quantise(e, ec)
    assert C.mg_fuzzy_infer_q12(c, x_e[0], x_ec[0]) == py.infer_q12(x_e[0], x_ec[0])
    assert C.mg_fuzzy_u_mrad(c, e, ec) == py.u_mrad(e, ec)
    left, right = FFI.new("int32_t *"), FFI.new("int32_t *")
    C.mg_fuzzy_wheels_mm_s(c, u, left, right)
    assert (left[0], right[0]) == py.wheels_mm_s(u)
    assert c.no_rule_fired == py.no_rule_fired == 0


@SETTINGS
@given(FUZZY_PARAMS, st.lists(st.tuples(st.integers(0, 100_000), st.none()
                                        | st.integers(-4000, 4000),
                                        st.none() | st.integers(0, 90)),
                              min_size=10, max_size=40))
def test_fuzzy_approach_steps(params, steps):
    """e_c from successive e (none when the clock has not moved), the marker lost and the
    stop at T_d: the same commands step by step."""
    py = fuzzy.FuzzyApproach(params)
    c = FFI.new("mg_fuzzy_approach_t *")
    C.mg_fuzzy_approach_init(c, _c_params(params))
    t_us = 0
    for dt, e, d_pixel in steps:
        t_us += dt
        got = C.mg_fuzzy_approach_step(c, t_us, e is not None, e or 0, d_pixel is not None,
                                       d_pixel or 0)
        want = py.step(t_us, e, d_pixel)
        assert (got.left_mm_s, got.right_mm_s, got.u_mrad, bool(got.stop)) == (
            want.left_mm_s, want.right_mm_s, want.u_mrad, want.stop)
    assert hostc.ops_tuple(C.mg_fuzzy_eval_ops()) == fuzzy.EVAL_OPS.as_tuple()
