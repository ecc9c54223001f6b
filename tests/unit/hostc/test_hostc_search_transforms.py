"""The C host's Fig. 5 search (hostc/search.c), camera transform (hostc/transforms.c, eqs.
(1)-(3) of 000) and ranging (hostc/ranging.c, 000 and 002 section 4) against host/search.py,
host/transforms.py and host/ranging.py."""

from __future__ import annotations

from hypothesis import assume, given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.host import coverage, kinematics, ranging, search, transforms

FFI, C = hostc.lib()
SETTINGS = examples(150)
MRAD = st.integers(-3500, 3500)


def _geom(g):
    return FFI.new("mg_arm_geometry_t *", (g.l1_mm_q4, g.l2_mm_q4, g.l3_mm_q4))


@SETTINGS
@given(st.tuples(*[st.integers(-5000, 5000)] * 3), MRAD, MRAD, MRAD, MRAD,
       st.sampled_from([kinematics.PAPER_000, kinematics.PAPER_002]))
def test_camera_to_platform(p, t2, t3, t4, t5, g):
    out = FFI.new("int32_t[3]")
    C.mg_camera_to_platform_mm(p, _geom(g), t2, t3, t4, t5, out)
    assert tuple(out) == transforms.camera_to_platform_mm(p, g, t2, t3, t4, t5)
    C.mg_platform_offset_to_platform_mm(p, _geom(g), t2, t3, t4, t5, out)
    assert tuple(out) == transforms.platform_offset_to_platform_mm(p, g, t2, t3, t4, t5)
    C.mg_paper_cam_to_cv(p, out)
    assert tuple(out) == transforms.paper_cam_to_cv(*p)
    m = FFI.new("mg_mat_q12")
    C.mg_r_c_r_q12(t2 + t3 + t4, t5, m)
    assert tuple(tuple(r) for r in m) == transforms.r_c_r_q12(t2 + t3 + t4, t5)


@SETTINGS
@given(st.tuples(*[st.integers(-5000, 5000)] * 3), st.lists(st.integers(400, 2600),
                                                           min_size=6, max_size=6))
def test_camera_to_platform_from_telemetry(p, pulses):
    out = FFI.new("int32_t[3]")
    ok = C.mg_camera_to_platform_from_servo_us(p, _geom(kinematics.PAPER_000), pulses, out)
    try:
        want = transforms.camera_to_platform_from_servo_us(p, kinematics.PAPER_000, pulses)
    except ValueError:
        assert ok == 0
        return
    assert ok == 1 and tuple(out) == want
    assert hostc.ops_tuple(C.mg_camera_to_platform_ops()) == (
        transforms.camera_to_platform_ops().as_tuple())


@st.composite
def search_params(draw):
    lo = draw(st.integers(-3000, -1000))
    lo5 = draw(st.integers(-1400, 0))
    try:
        return search.SearchParams(
            lo, lo + draw(st.integers(1, 800)), draw(st.integers(60, 400)), lo5,
            lo5 + draw(st.integers(1, 2000)), draw(st.integers(150, 600)),
            draw(st.integers(-500, 0)), draw(st.integers(0, 3000)), draw(st.integers(1, 2000)),
            tuple(draw(st.lists(st.integers(-3200, -900), min_size=1, max_size=4))),
            draw(st.integers(1, 2000)), draw(st.integers(0, 2)), draw(st.integers(1, 2)),
            draw(st.sampled_from([0, 300, 1800])), draw(st.integers(0, 1)),
            draw(st.integers(200, 1400)), draw(st.integers(0, 2)), draw(st.integers(1, 3)),
            draw(st.integers(10_000, 100_000)), draw(st.integers(1000, 9000)),
            cover_mm=draw(st.sampled_from([0, 0, 1000, 2500, 4500]) | st.integers(0, 6000)),
            view_mm=draw(st.sampled_from([1100]) | st.integers(600, 2000)),
            chord_mm=draw(st.sampled_from([1500]) | st.integers(800, 3000)),
            wander_frames_per_pose=draw(st.integers(1, 3)),
            wander_d_theta5_mrad=draw(st.sampled_from([200, 350]) | st.integers(150, 700)),
            outward_from_mm=draw(st.sampled_from([0, 0, 1000, 3000]) | st.integers(0, 6000)),
            outward_inward_mrad=draw(st.sampled_from([0, 350, 700]) | st.integers(0, 1400)),
            round_tries=draw(st.integers(0, 3)),
            edge_mm=draw(st.sampled_from([0, 0, 900]) | st.integers(0, 3000)))
    except ValueError:
        assume(False)


def _c_params(p):
    levels = list(p.coarse_theta2_mrad)
    return FFI.new("mg_search_params_t *", {
        "theta2_min_mrad": p.theta2_min_mrad, "theta2_max_mrad": p.theta2_max_mrad,
        "d_theta2_mrad": p.d_theta2_mrad, "theta5_min_mrad": p.theta5_min_mrad,
        "theta5_max_mrad": p.theta5_max_mrad, "d_theta5_mrad": p.d_theta5_mrad,
        "theta3_mrad": p.theta3_mrad, "theta4_mrad": p.theta4_mrad,
        "base_turn_mrad": p.base_turn_mrad, "n_coarse": len(levels),
        "coarse_theta2_mrad": levels, "coarse_base_turn_mrad": p.coarse_base_turn_mrad,
        "dense_cycles": p.dense_cycles, "turns_per_wander": p.turns_per_wander,
        "wander_mm": p.wander_mm, "wander_sweep": p.wander_sweep,
        "wander_theta5_mrad": p.wander_theta5_mrad, "stop_cycles": p.stop_cycles,
        "frames_per_pose": p.frames_per_pose, "frame_period_us": p.frame_period_us,
        "servo_speed_mrad_per_s": p.servo_speed_mrad_per_s, "cover_mm": p.cover_mm,
        "view_mm": p.view_mm, "chord_mm": p.chord_mm,
        "wander_frames_per_pose": p.wander_frames_per_pose,
        "wander_d_theta5_mrad": p.wander_d_theta5_mrad, "outward_from_mm": p.outward_from_mm,
        "outward_inward_mrad": p.outward_inward_mrad, "round_tries": p.round_tries,
        "edge_mm": p.edge_mm})


def _cmd(c) -> tuple[int, ...]:
    return (c.theta2_mrad, c.theta3_mrad, c.theta4_mrad, c.theta5_mrad, c.base_turn_mrad,
            c.pose_index, c.cycle, c.drive_mm)


@SETTINGS
@given(search_params(), st.integers(-3500, 0), st.integers(-1500, 1500), st.booleans(),
       st.booleans())
def test_one_cycle(p, th2, th5, upward, coarse):
    poses = FFI.new("int32_t[512][2]")
    overflow = FFI.new("int32_t *")
    n = C.mg_search_cycle(_c_params(p), th2, th5, upward, coarse, poses, 512, overflow)
    want = search.search_cycle(p, th2, th5, upward, coarse)
    assume(len(want) <= 512)
    assert [tuple(poses[i]) for i in range(n)] == want and overflow[0] == 0


@SETTINGS
@given(search_params(), st.integers(-3500, 0), st.integers(-1500, 1500),
       st.lists(st.tuples(st.sampled_from(["step", "step", "step", "turned", "wandered",
                                           "blocked", "stuck", "resumed", "looked",
                                           "restart"]),
                          st.integers(0, 3_000_000),
                          st.none() | st.tuples(st.integers(-6000, 6000),
                                                st.integers(-6000, 6000),
                                                st.integers(-3142, 3141))),
                min_size=30, max_size=80))
def test_search_over_time(p, th2, th5, calls):
    """Steps at increasing times with the base's pose (the rings' legs), the caller's base
    turns and wanders, legs stopped by an obstacle (with a way round it or none) and driven
    round or ended in a look, pauses: the same commands (poses, turns, drives, cycles) every
    call, the same stations and legs passing beside an obstacle."""
    py = search.ArmSearch(p, th2, th5, 0)
    c = FFI.new("mg_arm_search_t *")
    C.mg_search_init(c, _c_params(p), th2, th5, 0)
    assume(c.overflow == 0)
    t = 0
    for kind, dt, pose in calls:
        t += dt
        if kind == "step":
            want = py.step(t, pose)
            assert _cmd(C.mg_search_step(c, t, pose or FFI.NULL)) == (
                want.theta2_mrad, want.theta3_mrad, want.theta4_mrad, want.theta5_mrad,
                want.base_turn_mrad, want.pose_index, want.cycle, want.drive_mm)
        elif kind == "turned":
            py.base_turn_done(t)
            C.mg_search_base_turn_done(c, t)
        elif kind == "wandered":
            py.wander_done(t)
            C.mg_search_wander_done(c, t)
        elif kind in ("blocked", "stuck"):
            way = kind == "blocked"
            assert bool(C.mg_search_wander_blocked(c, t, way)) == py.wander_blocked(t, way)
        elif kind == "resumed":
            py.wander_resume(t)
            C.mg_search_wander_resume(c, t)
        elif kind == "looked":
            py.wander_look(t)
            C.mg_search_wander_look(c, t)
        else:
            py.restart_dwell(t)
            C.mg_search_restart_dwell(c, t)
        assert (bool(c.turning or c.wandering), bool(c.wandering), c.wanders, c.covered,
                c.side, bool(C.mg_search_passing(c))) == (
            py.turning, py.wandering, py.wanders, py.covered, py.sweep_side, py.passing)
        xy = FFI.new("int32_t[2]")
        assert (tuple(xy) if C.mg_search_station_xy(c, xy) else None) == py.station_xy
    assert c.overflow == 0


@SETTINGS
@given(st.integers(-100, 8000), st.sampled_from([-10, 0]) | st.integers(300, 3000),
       st.sampled_from([-10, 0]) | st.integers(300, 4000),
       st.sampled_from([-10, 0, 900]) | st.integers(0, 3000))
def test_ring_stations(radius, view, chord, edge):
    out = FFI.new("int32_t[256][2]")
    overflow = FFI.new("int32_t *")
    n = C.mg_ring_stations(radius, view, chord, edge, out, 256, overflow)
    try:
        want = coverage.ring_stations(radius, view, chord, edge)
    except ValueError:
        assert n == -1
        return
    assume(len(want) <= 256 and overflow[0] == 0)
    assert [tuple(out[i]) for i in range(n)] == want


def test_the_shipped_rings_fit():
    """002's disc (2.5 m) and the default one (4.5 m) at the default strip and chord."""
    for radius in (2500, 4500):
        out, overflow = FFI.new("int32_t[256][2]"), FFI.new("int32_t *")
        n = C.mg_ring_stations(radius, 1100, 1500, 0, out, 256, overflow)
        assert overflow[0] == 0 and n == len(coverage.ring_stations(radius, 1100, 1500)) >= 7


@SETTINGS
@given(st.tuples(st.integers(-10**6, 10**6), st.integers(-10**6, 10**6), st.integers(-4000, 4000)),
       st.tuples(st.integers(-10**6, 10**6), st.integers(-10**6, 10**6)))
def test_legs_and_the_start_frame(pose, xy):
    turn, drive, out = FFI.new("int32_t *"), FFI.new("int32_t *"), FFI.new("int32_t[2]")
    C.mg_leg_to(pose, xy, turn, drive)
    assert (turn[0], drive[0]) == coverage.leg_to(pose, xy)
    C.mg_to_odometry(pose, xy, out)
    assert tuple(out) == coverage.to_odometry(pose, xy)


def test_search_defaults():
    c, want = FFI.new("mg_search_params_t *"), _c_params(search.SearchParams())
    C.mg_search_params_default(c)
    for name, _ in FFI.typeof("mg_search_params_t").fields:
        if name == "coarse_theta2_mrad":
            assert list(c.coarse_theta2_mrad)[:c.n_coarse] == list(
                search.SearchParams().coarse_theta2_mrad)
        else:
            assert getattr(c, name) == getattr(want, name), name


@SETTINGS
@given(st.integers(-2000, 60_000), st.integers(-8000, 8000), st.integers(-8000, 8000),
       st.integers(-3200, 3200), st.integers(-1600, 1600), st.integers(100, 900),
       st.integers(1000, 60_000))
def test_ranging_from_size_and_002_as_printed(d_pixel_q4, u_q4, v_q4, alpha, theta5, f_px,
                                              d_um):
    """002 section 4 as printed and the pinhole range of 000; a pixel size <= 0 is refused."""
    out = FFI.new("int32_t *")
    r = FFI.new("mg_range_002_t *")
    ok = C.mg_range_from_size_mm(d_um, f_px, d_pixel_q4, out)
    ok2 = C.mg_range_002(d_pixel_q4, u_q4, v_q4, alpha, theta5, f_px, 160, 120, d_um, r)
    if d_pixel_q4 <= 0:
        assert ok == ok2 == 0
        return
    assert out[0] == ranging.range_from_size_mm(d_um, f_px, d_pixel_q4)
    want = ranging.range_002(d_pixel_q4, u_q4, v_q4, alpha, theta5, f_px, 160, 120, d_um)
    assert (r.d_oc_mm, r.theta_v_mrad, r.theta_h_mrad, r.x_oc_mm, r.y_oc_mm, r.z_oc_mm) == (
        want.d_oc_mm, want.theta_v_mrad, want.theta_h_mrad, want.x_oc_mm, want.y_oc_mm,
        want.z_oc_mm)
    assert hostc.ops_tuple(C.mg_range_002_ops()) == ranging.range_002_ops().as_tuple()
    assert hostc.ops_tuple(C.mg_locate_ring_pair_ops()) == (
        ranging.locate_ring_pair_ops().as_tuple())


@SETTINGS
@given(st.integers(-400, 400), st.integers(-400, 400), st.integers(-3200, 3200),
       st.integers(0, 10_000))
def test_platform_bearing(cam_x, cam_y, bearing, dist):
    assert C.mg_platform_bearing_mrad(cam_x, cam_y, bearing, dist) == (
        ranging.platform_bearing_mrad(cam_x, cam_y, bearing, dist))
