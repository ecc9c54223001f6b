"""The wandering search (host.search, host/task/search.py): 000 §II "wanders to search"."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from mobigrasp.host import coverage
from mobigrasp.host import search as se
from mobigrasp.host.task import Task, TaskInputs
from mobigrasp.host.task.params import TaskParams

P = se.SearchParams(cover_mm=0)  # the square spiral; the rings: test_coverage.py


def _run_to_move(s: se.ArmSearch, t: int) -> tuple[se.SearchCommand, int]:
    """Step the pattern in 10 ms steps until it asks the base to move."""
    while True:
        c = s.step(t)
        if c.base_turn_mrad or c.drive_mm:
            return c, t
        t += 10_000
        assert t < 200_000_000


def test_coarse_cycle_visits_only_the_coarse_levels_nearest_first():
    poses = se.search_cycle(P, -2800, -800, upward=True, coarse=True)
    levels = list(dict.fromkeys(t2 for t2, _ in poses))
    assert levels == sorted(P.coarse_theta2_mrad)  # from -2800 the lowest level is nearest
    poses = se.search_cycle(P, -2100, 800, upward=False, coarse=True)
    assert list(dict.fromkeys(t2 for t2, _ in poses)) == sorted(P.coarse_theta2_mrad,
                                                                 reverse=True)
    assert poses[0][1] == 800 and poses[8][1] == -800  # boustrophedon from theta5s
    dense = se.search_cycle(P, -2100, -800, upward=False)
    assert len(poses) * 3 < len(dense)


P_STOPS = se.SearchParams(wander_sweep=0, stop_cycles=4, cover_mm=0)  # a look-around at every stop


def test_a_look_around_then_a_wander_then_coarse_cycles_and_a_longer_spiral():
    P = P_STOPS
    s = se.ArmSearch(P, -2100, -800, now_us=0)
    t = 0
    turns = []
    for k in range(1, P.turns_per_wander):
        c, t = _run_to_move(s, t)
        assert c.base_turn_mrad and c.drive_mm == 0 and c.cycle == k and not s.wandering
        turns.append(c.base_turn_mrad)
        s.base_turn_done(t)
        assert {t2 for t2, _ in s._poses} == set(P.coarse_theta2_mrad)  # coarse from now on
    # first turn as the paper's, the rest coarse; with the ~60 degrees each cycle sees on
    # either side of its heading the headings cover the whole turn
    assert turns == [P.base_turn_mrad] + [P.coarse_base_turn_mrad] * (P.turns_per_wander - 2)
    assert sum(turns) + 2 * 1047 >= 6283 - 5
    c, t = _run_to_move(s, t)
    assert c.drive_mm == P.wander_mm and c.base_turn_mrad == 0
    assert c.cycle == P.turns_per_wander and s.turning and s.wandering
    assert (c.theta2_mrad, c.theta5_mrad) == (P.coarse_theta2_mrad[0], P.theta5_max_mrad)
    # the request holds until the caller reports the wander done; a turn report does not end it
    s.base_turn_done(t + 5_000_000)
    assert s.step(t + 5_000_000).drive_mm == P.wander_mm
    s.wander_done(t + 5_000_000)
    c2 = s.step(t + 5_000_000)
    assert c2.drive_mm == 0 and c2.base_turn_mrad == 0 and not s.turning and s.wanders == 1
    assert (c2.theta2_mrad, c2.theta5_mrad) == (P.coarse_theta2_mrad[0], P.theta5_max_mrad)
    legs = [P.wander_mm]
    t += 5_000_000
    for _ in range(3):
        for _ in range(1, P.turns_per_wander):
            c, t = _run_to_move(s, t)
            assert c.base_turn_mrad == P.coarse_base_turn_mrad
            s.base_turn_done(t)
        c, t = _run_to_move(s, t)
        legs.append(c.drive_mm)
        s.wander_done(t)
    assert legs == [P.wander_mm, P.wander_mm, 2 * P.wander_mm, 2 * P.wander_mm]


def _to_first_wander(p: se.SearchParams) -> tuple[se.ArmSearch, se.SearchCommand, int]:
    s = se.ArmSearch(p, -2100, -800, now_us=0)
    t = 0
    while True:
        c, t = _run_to_move(s, t)
        if c.drive_mm:
            return s, c, t
        s.base_turn_done(t)


def test_the_wander_sweeps_the_waist_at_the_far_level_both_ways_while_driving():
    s, c, t = _to_first_wander(P)
    assert c.drive_mm == P.wander_mm and s.wandering and s.turning
    seen = set()
    for k in range(0, 12_000_000, 20_000):  # 12 s of driving
        c = s.step(t + k)
        assert c.drive_mm == P.wander_mm and c.base_turn_mrad == 0
        assert c.theta2_mrad == P.coarse_theta2_mrad[0]  # the far level only
        seen.add(c.theta5_mrad)
    w = P.wander_theta5_mrad
    assert {-w, 0, w} <= seen and len(seen) == 2 * w // P.d_theta5_mrad + 1
    # one pose per dwell, as in a cycle: a full sweep one way takes 15 dwells
    t5 = [s.step(t + 12_000_000 + k).theta5_mrad for k in range(0, 3_000_000, 10_000)]
    changes = sum(1 for a, b in zip(t5, t5[1:], strict=False) if a != b)
    dwell = s.dwell_us((0, 0), (0, P.d_theta5_mrad))
    assert abs(changes - 3_000_000 // dwell) <= 1
    # the old behaviour holds the camera left
    s0, c0, t0 = _to_first_wander(se.SearchParams(wander_sweep=0, cover_mm=0))
    assert {s0.step(t0 + k).theta5_mrad for k in range(0, 5_000_000, 50_000)} == \
        {P.theta5_max_mrad}


def test_after_the_first_look_around_the_wander_only_turns_at_the_corners():
    s, c, t = _to_first_wander(P)
    cycles = c.cycle
    legs, turns = [c.drive_mm], []
    for _ in range(5):
        t += 5_000_000
        s.wander_done(t)
        c = s.step(t)
        # a corner: a turn, no drive, the arm holds the wander pose, no search cycle
        assert c.drive_mm == 0 and c.base_turn_mrad == P.coarse_base_turn_mrad and s.turning
        assert not s.wandering and c.cycle == cycles
        assert s.step(t + 3_000_000) == c  # holds until the turn is reported
        turns.append(c.base_turn_mrad)
        s.base_turn_done(t + 3_000_000)
        c = s.step(t + 3_000_000)
        assert s.wandering and c.drive_mm
        legs.append(c.drive_mm)
    w = P.wander_mm
    assert legs == [w, w, 2 * w, 2 * w, 3 * w, 3 * w]  # counter-clockwise expanding square
    assert all(t == 1571 for t in turns)


def test_stop_cycles_look_around_at_each_stop():
    p = se.SearchParams(stop_cycles=2, cover_mm=0)
    s, c, t = _to_first_wander(p)
    s.wander_done(t + 1_000_000)
    c = s.step(t + 1_000_000)
    assert not s.turning and c.drive_mm == 0  # a search cycle here
    c, t = _run_to_move(s, t + 1_000_000)
    assert c.base_turn_mrad and not c.drive_mm  # one turn between the two cycles
    s.base_turn_done(t)
    c, t = _run_to_move(s, t)
    assert c.drive_mm == p.wander_mm  # then the next leg


def test_one_coarse_level_from_the_middle_still_sweeps_both_ends():
    p = se.SearchParams(coarse_theta2_mrad=(-2400,))
    poses = se.search_cycle(p, -2100, 0, coarse=True)
    assert {t5 for _, t5 in poses} >= {p.theta5_min_mrad, 0, p.theta5_max_mrad}
    assert {t2 for t2, _ in poses} == {-2400}
    dense = se.search_cycle(se.SearchParams(dense_cycles=1), -2100, 0)
    first = se.ArmSearch(se.SearchParams(dense_cycles=1), -2100, 0, now_us=0)
    assert first._poses == dense and se.ArmSearch(P, -2100, 0, now_us=0)._poses == \
        se.search_cycle(P, -2100, 0, coarse=True)


def test_wander_off_means_turns_forever():
    p = se.SearchParams(wander_mm=0, theta2_min_mrad=-2200, d_theta5_mrad=800)
    s = se.ArmSearch(p, -2100, -800, now_us=0)
    t = 0
    for _ in range(3 * p.turns_per_wander):
        c, t = _run_to_move(s, t)
        assert c.base_turn_mrad and not c.drive_mm
        s.base_turn_done(t)


def test_bad_wander_params():
    with pytest.raises(ValueError, match="wander_mm"):
        se.SearchParams(wander_mm=-1)
    with pytest.raises(ValueError, match="turns_per_wander"):
        se.SearchParams(turns_per_wander=0)
    with pytest.raises(ValueError, match="wander_sweep"):
        se.SearchParams(wander_sweep=2)
    with pytest.raises(ValueError, match="stop_cycles"):
        se.SearchParams(stop_cycles=-1)
    with pytest.raises(ValueError, match="wander_theta5_mrad"):
        se.SearchParams(wander_theta5_mrad=0)
    assert se.SearchParams(coarse_theta2_mrad=(-2500, -3000, -2900)).coarse_theta2_mrad == \
        (-2500, -2800)  # clamped into the theta2 range, duplicates dropped
    with pytest.raises(ValueError, match="coarse_theta2_mrad"):
        se.SearchParams(coarse_theta2_mrad=())
    assert se.SearchParams(coarse_theta2_mrad=[-2300]).coarse_theta2_mrad == (-2300,)


def _task_to_wander(sonar: tuple) -> tuple[Task, int]:
    # a two-level, three-pose pattern and a wander after every cycle: the wander comes quickly
    task = Task("000", {"search": {"theta2_min_mrad": -2200, "d_theta5_mrad": 800,
                                   "turns_per_wander": 1, "wander_mm": 500, "cover_mm": 0,
                                   "coarse_theta2_mrad": (-2200,)}})
    t = 0
    while t < 20_000_000:
        out = task.step(t, TaskInputs(sonar_mm=sonar))
        if out.wheels_mmps != (0, 0) and out.wheels_mmps is not None:
            return task, t
        t += 20_000
    raise AssertionError("no wander within 20 s")


def test_task_wanders_straight_ahead_until_odometry_says_the_distance_is_done():
    task, t = _task_to_wander(())
    out = task.step(t + 20_000, TaskInputs(x_mm=200, y_mm=0))
    v = task.p.wander_mmps
    assert out.wheels_mmps == (v, v) and out.state == "SEARCH"
    # the camera looks on the way
    assert task.detectors_needed() == ["radial_symbol", "radial_cut"]
    out = task.step(t + 40_000, TaskInputs(x_mm=300, y_mm=400))  # 500 mm from the start
    assert out.wheels_mmps == (0, 0) and task.search.wanders == 1 and not task.search.wandering
    # a corner of the spiral: the base turns left in place, the camera looking, then drives
    # the next leg
    out = task.step(t + 60_000, TaskInputs(x_mm=300, y_mm=400))
    assert out.wheels_mmps[0] < 0 < out.wheels_mmps[1]
    assert task.detectors_needed() == ["radial_symbol", "radial_cut"]
    out = task.step(t + 80_000, TaskInputs(x_mm=300, y_mm=400, heading_mrad=1571))
    out = task.step(t + 100_000, TaskInputs(x_mm=300, y_mm=400, heading_mrad=1571))
    assert out.wheels_mmps == (v, v) and task.search.wandering


def test_the_search_s_base_turns_may_have_their_own_wheel_speed():
    """SEARCH's turns on the spot (the look-around's, the rings' corners) at
    ``search_turn_wheel_mmps`` when set, else ``turn_wheel_mmps`` (80 mm/s; every method: 000's
    at 160 mm/s lost a control seed, docs/task.md "000: the last ring nearer the edge")."""
    for params, want in (({}, 80), ({"search_turn_wheel_mmps": 160}, 160)):
        task, t = Task("000", params), 0
        assert task.p.turn_wheel_mmps == 80
        while t < 20_000_000:
            out = task.step(t, TaskInputs(sonar_mm=(65535,) * 5))
            if out.wheels_mmps not in (None, (0, 0)):
                break
            t += 20_000
        assert out.state == "SEARCH" and task.search.turning and not task.search.wandering
        assert out.wheels_mmps == (-want, want), (params, out.wheels_mmps)  # left, on the spot


def test_a_target_seen_while_the_base_turns_stops_the_turn_to_confirm_it():
    import detections as det

    task, t = _task_to_wander(())
    task.step(t + 20_000, TaskInputs(x_mm=300, y_mm=400))  # the leg is done
    out = task.step(t + 40_000, TaskInputs(x_mm=300, y_mm=400))
    assert out.wheels_mmps[0] < 0 < out.wheels_mmps[1] and task.search.turning  # the corner
    seen = {"radial_symbol": det.radial(160 * 16, 150 * 16, 900)}
    out = task.step(t + 60_000, TaskInputs(x_mm=300, y_mm=400, heading_mrad=400,
                                           detections=seen))
    assert out.wheels_mmps == (0, 0) and task.confirm_until is not None  # stop, look again
    out = task.step(t + 80_000, TaskInputs(x_mm=300, y_mm=400, heading_mrad=400))
    assert out.wheels_mmps == (0, 0) and out.state == "SEARCH"


def test_task_wander_stops_short_when_a_front_sonar_sees_something():
    clear = (65535,) * 5
    task, t = _task_to_wander(clear)
    out = task.step(t + 20_000, TaskInputs(x_mm=100, sonar_mm=clear))
    assert out.wheels_mmps[0] > 0
    # a side sonar (index 0, to the right) close by does not stop the wander
    out = task.step(t + 40_000, TaskInputs(x_mm=120, sonar_mm=(200,) + (65535,) * 4))
    assert out.wheels_mmps[0] > 0 and task.search.wanders == 0
    near = task.p.wander_clear_mm - 1
    out = task.step(t + 60_000, TaskInputs(x_mm=140, sonar_mm=(65535, 65535, near, 65535, 65535)))
    assert out.wheels_mmps == (0, 0) and task.search.wanders == 1


def _on_the_leg(s: se.ArmSearch, t: int) -> None:
    """The base has turned toward the station (if it had to): the leg is driven."""
    if not s.wandering:
        s.base_turn_done(t)
    assert s.wandering


def test_a_last_ring_leg_stopped_by_an_obstacle_goes_round_it_twice_at_most():
    p = se.SearchParams(round_tries=2, outward_from_mm=3000)
    s, t = _on_an_outward_leg(p)
    station, wanders = s.station_xy, s.wanders
    assert station is not None and not s.passing
    assert s.wander_blocked(t)  # go round, then the same station
    assert s.passing and s.wandering and s.wanders == wanders
    s.wander_resume(t)
    _on_the_leg(s, t)
    assert s.station_xy == station and s.wander_blocked(t)  # the second try
    s.wander_resume(t)
    _on_the_leg(s, t)
    assert not s.wander_blocked(t)  # tries used up: the next station, still passing
    assert s.station_xy != station and s.wanders == wanders + 1 and s.passing
    _on_the_leg(s, t)
    assert not s.wander_blocked(t, can_round=True) and s.wanders == wanders + 2
    _on_the_leg(s, t)
    s.wander_done(t)  # a leg that ends unblocked: tries again, no more passing
    assert not s.passing
    _on_the_leg(s, t)
    assert not s.wander_blocked(t, can_round=False)  # no way round: the next station
    # a leg sweeping both sides (the first ring's), or round_tries 0: the next station
    for q, on_leg in ((p, _to_first_wander), (replace(p, round_tries=0), _on_an_outward_leg)):
        got = on_leg(q)
        s, t = got[0], got[-1]
        station = s.station_xy
        assert not s.wander_blocked(t) and s.station_xy != station and not s.passing
    with pytest.raises(ValueError, match="round_tries"):
        se.SearchParams(round_tries=-1)


def _move(task: Task, t: int, pose: list, sonar: tuple) -> tuple:
    """One 20 ms step with ``sonar``; the base's pose follows the wheels (a turn in place 40
    mrad a step, a drive its speed straight ahead)."""
    out = task.step(t, TaskInputs(x_mm=pose[0], y_mm=pose[1], heading_mrad=pose[2],
                                  sonar_mm=sonar))
    left, right = out.wheels_mmps
    if left == right:
        pose[0] += round(left * 0.02 * math.cos(pose[2] / 1000))
        pose[1] += round(left * 0.02 * math.sin(pose[2] / 1000))
    else:
        pose[2] += 40 if right > left else -40
    return out


def test_000_goes_round_an_obstacle_on_an_outward_leg_and_passes_beside_it():
    far, v = 65535, 350
    clear, ahead, beside = (far,) * 5, (far, far, 350, far, far), (far, far, far, 300, far)
    # a one-level look-around; the first ring's legs already sweep outward (outward_from_mm)
    task = Task("000", {"search": {"theta2_min_mrad": -2200, "d_theta5_mrad": 800,
                                   "turns_per_wander": 1, "coarse_theta2_mrad": (-2200,),
                                   "outward_from_mm": 1000}})
    t, pose = 0, [0, 0, 0]
    while task.search is None or task.search.sweep_side == 0 or not task.search.wandering:
        _move(task, t, pose, clear)  # the look-around, the first leg out, the corner
        t += 20_000
        assert t < 60_000_000
    station = task.search.station_xy
    out = _move(task, t, pose, ahead)
    assert out.wheels_mmps == (0, 0) and out.detail["wander_blocked"] is True
    round_to = out.detail["wander_round_mrad"]
    # the free sonar direction nearest the station: 45 degrees aside
    assert abs(abs(round_to - pose[2]) - 785) <= 40 and task.search.station_xy == station
    start = tuple(pose[:2])
    while task.wander_round is not None:  # turn, then drive detour_mm
        t += 20_000
        _move(task, t, pose, clear)
    assert math.dist(start, pose[:2]) >= task.p.detour_mm
    assert task.search.station_xy == station and task.search.passing
    while not task.search.wandering:  # the turn toward the same station
        t += 20_000
        _move(task, t, pose, clear)
    for _ in range(5):  # beside the obstacle it drives on
        t += 20_000
        assert _move(task, t, pose, beside).wheels_mmps == (v, v)
    t += 20_000
    out = _move(task, t, pose, ahead)  # in its way (within 400 mm): stops, the second try
    assert out.wheels_mmps == (0, 0) and "wander_round_mrad" in out.detail


def test_002_keeps_the_papers_first_cycle_and_a_level_look_and_overrides_merge():
    from mobigrasp.host.task import TaskParams

    p = TaskParams.for_method("002", {"search": {"wander_mm": 0}})
    sp = se.SearchParams(**p.search)
    assert sp.dense_cycles == 1 and -2100 in sp.coarse_theta2_mrad and sp.wander_mm == 0
    # 000's own: the wander's sweep alone (host/task/method000.py)
    assert se.SearchParams(**TaskParams.for_method("000").search) == se.SearchParams(
        wander_frames_per_pose=1, wander_d_theta5_mrad=350, outward_from_mm=3000,
        outward_inward_mrad=1050, edge_mm=900, round_tries=2)
    assert sp.cover_mm == 2500  # 002 gives up once the rings covered 2.5 m (method002.py)


def test_an_unconfirmed_sighting_seen_again_at_the_same_place_counts():
    from types import SimpleNamespace

    from mobigrasp.host.task import TaskParams
    from mobigrasp.host.task.search import SEARCH

    p = TaskParams.for_method("000")
    t = SimpleNamespace(p=p, sighting=None, obj=(1800, 900))
    assert not SEARCH.seen_there_before(t)  # nothing seen before
    t.sighting = (1800 + p.sighting_match_mm, 900)
    assert SEARCH.seen_there_before(t)
    t.sighting = (1800, 900 + p.sighting_match_mm + 1)
    assert not SEARCH.seen_there_before(t)


def test_detour_heads_for_the_free_sonar_direction_nearest_the_object():
    from mobigrasp.host.task.method001 import detour_heading
    from mobigrasp.host.task.sonar_guard import sonar_angles_mrad

    assert sonar_angles_mrad(5) == [-1571, -786, 0, 785, 1571]
    # facing +x, object straight ahead; front and front-left blocked, front-right free
    inp = TaskInputs(x_mm=0, y_mm=0, heading_mrad=0, sonar_mm=(65535, 2000, 400, 500, 65535))
    d = detour_heading(inp, (1500, 0), 900)
    assert d["drive"] and d["heading_mrad"] == -786  # 45 degrees right
    # object to the left: the left sonar is the free one nearest to it
    d = detour_heading(inp, (0, 1500), 900)
    assert d["drive"] and d["heading_mrad"] == 1571
    # nothing free: a quarter turn left without driving
    d = detour_heading(TaskInputs(sonar_mm=(300,) * 5), (1500, 0), 900)
    assert not d["drive"] and d["heading_mrad"] == 1571


def test_detour_turns_then_drives_its_length_then_ends():
    from types import SimpleNamespace

    from mobigrasp.host.task import TaskParams
    from mobigrasp.host.task.method001 import RULES, State001

    p = TaskParams.for_method("001")
    task = SimpleNamespace(p=p, wheels=None, ms=State001(
        detour={"heading_mrad": -786, "drive": True, "from": None}))
    free = (65535,) * 5
    assert not RULES.detour_step(task, TaskInputs(heading_mrad=0, sonar_mm=free))
    assert task.wheels == (p.turn_wheel_mmps, -p.turn_wheel_mmps)  # clockwise, to the right
    assert not RULES.detour_step(task, TaskInputs(heading_mrad=-760, sonar_mm=free))
    assert task.wheels == (p.wander_mmps, p.wander_mmps)
    assert not RULES.detour_step(task, TaskInputs(x_mm=200, y_mm=-200, heading_mrad=-760,
                                                  sonar_mm=free))
    assert RULES.detour_step(task, TaskInputs(x_mm=360, y_mm=-360, heading_mrad=-760,
                                              sonar_mm=free))
    assert task.wheels == (0, 0)
    # a front sonar seeing something close ends it early
    task.ms.detour = {"heading_mrad": 0, "drive": True, "from": None}
    assert RULES.detour_step(task, TaskInputs(sonar_mm=(65535, 65535, 300, 65535, 65535)))


# --- the strip the sweep sees while driving (a float reference of the camera) ---------------
SERVO_RAD_PER_S = (math.pi / 3.0) / 0.17  # the simulated servo (mcu_sim/world/actuators.py)
F_PX, U0_PX, SYMBOL_MM = 611, 160, 109  # 000's camera and radial symbol (000 §IV)
READ_M = (0.52, 1.1)  # the far level reads the symbol this far from the camera (host.search)
P000 = se.SearchParams(**TaskParams.for_method("000").search)


def _on_an_outward_leg(p: se.SearchParams) -> tuple[se.ArmSearch, int]:
    """The rings driven by a base that turns and drives at once, to the first leg whose sweep
    looks to one side alone."""
    s, c, t = _to_first_wander(p)
    x = y = h = 0
    while s.sweep_side == 0:
        x += round(c.drive_mm * math.cos(h / 1000))
        y += round(c.drive_mm * math.sin(h / 1000))
        s.step(t, (x, y, h))
        s.wander_done(t)
        c = s.step(t, (x, y, h))
        if c.base_turn_mrad:
            h += c.base_turn_mrad
            s.step(t, (x, y, h))
            s.base_turn_done(t)
            c = s.step(t, (x, y, h))
        assert s.wandering and not s.covered
    return s, t


def _strip_misses(s: se.ArmSearch, t0: int, speed_mmps: int, leg_s: int = 24,
                  latency_us: int = 20_000) -> dict[float, float]:
    """Drive ``s``'s wander straight on at ``speed_mmps`` for ``leg_s``: for each lateral
    offset (m, left positive) the share of the points along the leg's steady part that no
    settled frame (15 fps; the waist at the simulated servo's speed from ``latency_us`` after
    each 20 ms step's command) shows wholly within the symbol's reading range."""
    cmds = []
    for t in range(0, leg_s * 1_000_000, 20_000):
        th5 = s.step(t0 + t).theta5_mrad / 1000
        if not cmds or cmds[-1][1] != th5:
            cmds.append((t + latency_us, th5))
    frames = []
    for k in range(leg_s * 15):
        t = k * 1_000_000 // 15
        done = [c for c in cmds if c[0] <= t]
        if len(done) >= 2:
            (t1, a1), (_, a0) = done[-1], done[-2]
            if abs(a1 - a0) <= SERVO_RAD_PER_S * (t - t1) / 1e6:  # settled
                frames.append((speed_mmps * t / 1e9, a1))
    v = speed_mmps / 1000
    out = {}
    for yi in range(-105, 106, 5):
        y, miss, n = yi / 100, 0, 0
        for xi in range(int(6 * v * 100), int((leg_s - 4) * v * 100), 2):
            x, n = xi / 100, n + 1
            seen = False
            for bx, a in frames:
                d = math.hypot(x - bx, y)
                if READ_M[0] <= d <= READ_M[1]:
                    half = math.atan((U0_PX - SYMBOL_MM * F_PX / (2000 * d)) / F_PX)
                    if abs(math.atan2(y, x - bx) - a) <= half:
                        seen = True
                        break
            miss += not seen
        out[y] = miss / n
    return out


def test_the_sweep_while_driving_sees_a_strip_on_either_side():
    """000's sweep while driving (one frame per 0.35 rad pose) at its wander speed sees all
    but 3 % of the points within 0.85 m of the leg on either side (those few at 0.2-0.35 m,
    just past the near end of the reading range between two poses, and at 0.8-0.85 m); the
    sweep of two frames per 0.2 rad pose leaves more than 10 % unseen there at that speed
    (docs/task.md)."""
    speed = TaskParams.for_method("000").wander_mmps
    s, _, t = _to_first_wander(P000)
    assert s.sweep_side == 0
    misses = _strip_misses(s, t, speed)
    assert max(m for y, m in misses.items() if abs(y) <= 0.85) <= 0.03, misses
    old = replace(P000, wander_frames_per_pose=2, wander_d_theta5_mrad=200)
    s, _, t = _to_first_wander(old)
    assert max(m for y, m in _strip_misses(s, t, speed).items() if abs(y) <= 0.85) > 0.1


def test_the_last_ring_sweeps_outward_to_the_edge_and_its_inner_side_meets_the_first_ring():
    """The legs of the last ring (3.6 m, 0.9 m inside the 4.5 m disc's edge) sweep the outer
    side and 1.05 rad across alone: all but 3 % of the points to 0.9 m outward (the disc's
    edge) and 0.7 m inward are seen (those few at 0.25-0.35 m inward, just past the near end of
    the reading range, and at 0.7 m), which meets the first ring's strip (0.85 m outside its
    sides);
    the first ring sweeps both. 0.7 rad across saw 0.55 m inward: short of the first ring's
    strip from a ring at 3.6 m (docs/task.md "000: the last ring nearer the edge")."""
    tp = TaskParams.for_method("000")
    s, t = _on_an_outward_leg(P000)
    assert s.sweep_side == -1  # the rings turn counter-clockwise: the centre on the left
    misses = _strip_misses(s, t, tp.wander_mmps)
    assert max(m for y, m in misses.items() if -0.9 <= y <= 0.7) <= 0.03, misses
    stations = coverage.ring_stations(P000.cover_mm, P000.view_mm, P000.chord_mm, P000.edge_mm)
    sides = sorted({round(math.hypot((a[0] + b[0]) / 2, (a[1] + b[1]) / 2), -1)
                    for a, b in zip(stations, stations[1:], strict=False)
                    if abs(math.hypot(*a) - math.hypot(*b)) < 5})
    first, last = sides[0], sides[-1]
    assert first < P000.outward_from_mm <= last - 300  # the first ring sweeps both sides
    assert last + 900 >= P000.cover_mm  # the outer strip reaches the disc's edge
    assert first + 850 >= last - 700
    narrow = replace(P000, outward_inward_mrad=700)
    s, t = _on_an_outward_leg(narrow)
    misses = _strip_misses(s, t, tp.wander_mmps)
    assert misses[0.7] > 0.3 and first + 850 < last - 550, misses


def _drive(pose: tuple[int, int, int], wheels: tuple[int, int], dt_us: int) -> tuple:
    """The base's odometry after ``dt_us`` at ``wheels`` (mm/s; a 300 mm track)."""
    v, w = (wheels[0] + wheels[1]) / 2, (wheels[1] - wheels[0]) / 300
    h = pose[2] / 1000 + w * dt_us / 1e6
    return (round(pose[0] + v * math.cos(h) * dt_us / 1e6),
            round(pose[1] + v * math.sin(h) * dt_us / 1e6), round(h * 1000))


def far_sighting_run(task: Task, depth_mm: int, again_within_mm: int = 0,
                     until_us: int = 30_000_000) -> list:
    """000's SEARCH from the start with one frame at 2 s showing the radial symbol
    ``depth_mm`` off along the camera's axis; later frames show it again only while the
    camera's axle is within ``again_within_mm`` of the first estimate (0: never). The steps'
    (t_us, pose, outputs, the drive to a far sighting, the arm's targets), until APPROACH or
    ``until_us``."""
    import detections as det

    pose, wheels, first, out = (0, 0, 0), (0, 0), None, []
    for now in range(0, until_us, 20_000):
        dets = {}
        if now == 2_000_000 or (first is not None and again_within_mm and math.dist(
                pose[:2], first) <= again_within_mm):
            dets = {"radial_symbol": det.radial(160 * 16, 120 * 16, depth_mm)}
        res = task.step(now, TaskInputs(x_mm=pose[0], y_mm=pose[1], heading_mrad=pose[2],
                                        detections=dets))
        if first is None and task.obj is not None:
            first = task.obj
        out.append((now, pose, res, task.far, tuple(task.arm)))
        if res.state != "SEARCH":
            break
        wheels = res.wheels_mmps or wheels
        pose = _drive(pose, wheels, 20_000)
    return out


def _notes(steps: list, key: str) -> list:
    return [(now, pose, res.detail[key]) for now, pose, res, *_ in steps if key in res.detail]


def test_a_far_sighting_not_seen_again_is_driven_to_and_looked_at_then_the_search_goes_on():
    """000: a sighting 1.3 m off that the held pose does not read again is not dropped: the
    base turns toward it, drives until sighting_approach_mm from it, the waist looks at it and
    to either side, then the search resumes; nothing is claimed on the one frame."""
    task = Task("000")
    p = task.p
    steps = far_sighting_run(task, 1300)
    (t_far, _, far), = _notes(steps, "far_sighting")
    est = (far["x_mm"], far["y_mm"])
    assert far["dist_mm"] > p.sighting_approach_mm + p.sighting_match_mm and far["n"] == 1
    assert all(res.state == "SEARCH" for _, _, res, *_ in steps)  # one frame is no success
    (t_stop, pose, stop_mm), = _notes(steps, "far_stop_mm")
    # stopped within a step's drive of sighting_approach_mm, the estimate ahead
    assert p.sighting_approach_mm - 20 <= stop_mm <= p.sighting_approach_mm
    assert abs(math.dist(pose[:2], est) - stop_mm) <= 20
    # the look from there: five waist poses, the base standing, each held for its frames
    look = [(now, arm[5]) for now, _, _, far, arm in steps if far and far[0] == "look"]
    looks = list(dict.fromkeys(w for _, w in look))
    assert [w - looks[0] for w in looks] == [0, 350, -350, 700, -700]
    assert look[0][0] == t_stop and look[-1][0] - look[0][0] >= 5 * 2 * 66_667
    assert {res.wheels_mmps for now, _, res, *_ in steps if look[0][0] <= now <= look[-1][0]} \
        <= {(0, 0), None}
    assert t_far < t_stop and any(far and far[0] == "drive" for *_, far, _ in steps)
    # then the pattern again: no second drive to the same sighting
    assert task.far is None and task.far_count == 1 and len(_notes(steps, "far_sighting")) == 1


def test_a_far_sighting_seen_again_near_it_is_confirmed():
    """The drive toward a far sighting reads the symbol again nearer: it is approached."""
    task = Task("000")
    steps = far_sighting_run(task, 1300, again_within_mm=900)
    assert steps[-1][2].state == "APPROACH"
    ev = [e for _, _, res, *_ in steps for e in res.events if e.to_state == "APPROACH"]
    assert "(confirmed)" in ev[0].why or "(seen twice at that place)" in ev[0].why


def test_a_sighting_near_at_hand_is_dropped_as_before_and_001_002_never_drive_to_one():
    """A sighting within sighting_approach_mm + sighting_match_mm of the axle is not driven
    to (the look at rest was the nearer look); the other methods keep dropping them."""
    task = Task("000")
    steps = far_sighting_run(task, 700, until_us=6_000_000)
    assert _notes(steps, "search_seen") and not _notes(steps, "far_sighting")
    assert TaskParams.for_method("001").sighting_approach_mm == 0
    assert TaskParams.for_method("002").sighting_approach_mm == 0


def test_far_sightings_are_driven_to_at_most_sighting_approaches_times():
    task = Task("000", {"sighting_approaches": 0})
    assert not _notes(far_sighting_run(task, 1300, until_us=6_000_000), "far_sighting")


def test_a_leg_stopped_after_a_cut_symbol_faces_it_and_looks_around_there():
    """000: a wander leg stopped by a front sonar within CUT_LOOK_000_US of a frame showing
    the symbol cut by the frame's bottom (the object itself may have stopped it, too near for
    the sweep's far level): the base turns on the spot to face where the cut was seen, then a
    cycle at rest looks there before the next station; without such a cut lately (one at the
    top of the frame is far, a tall one an obstacle's face), the next station at once."""
    from mobigrasp.host.fixedpoint import atan2_mrad
    from mobigrasp.host.task.method000 import CUT_LOOK_000_US
    from mobigrasp.host.vision.radial_symbol import RadialCut

    clear = (65535,) * 5
    ahead = (65535, 65535, 300, 65535, 65535)
    for cut_age_us, cut_y, cut_h, looks in (
            (500_000, 200, 40, True), (CUT_LOOK_000_US + 100_000, 200, 40, False),
            (500_000, 0, 40, False), (500_000, 140, 100, False)):
        task = Task("000", {"search": {"theta2_min_mrad": -2200, "d_theta5_mrad": 800,
                                       "turns_per_wander": 1, "coarse_theta2_mrad": (-2200,)}})
        t, pose = 0, [0, 0, 0]
        while task.search is None or not task.search.wandering:
            _move(task, t, pose, clear)
            t += 20_000
        for _ in range(10):
            t += 20_000
            _move(task, t, pose, clear)
        # at the left border (and the bottom but for cut_y 0)
        cut = RadialCut(x=0, y=cut_y, w=130, h=cut_h, side=-1)
        out = task.step(t, TaskInputs(x_mm=pose[0], y_mm=pose[1], heading_mrad=pose[2],
                                      sonar_mm=clear, detections={"radial_cut": cut}))
        # its bearing: the waist of the frame's pose (right positive) and the half field of
        # view to the left
        want = -(task.arm_at(t - task.p.frame_latency_us)[5]
                 - atan2_mrad(task.cam.u0_px, task.cam.f_px))
        t += cut_age_us
        station = task.search.station_xy
        out = _move(task, t, pose, ahead)
        assert out.wheels_mmps == (0, 0) and out.detail["wander_blocked"] is True
        if not looks:
            assert "wander_look_mrad" not in out.detail and task.wander_look is None
            continue
        assert out.detail["wander_look_mrad"] == want and abs(want) > task.p.bearing_tol_mrad
        assert task.search.wandering  # the leg is not yet ended
        while task.wander_look is not None:  # the turn on the spot toward it
            t += 20_000
            out = _move(task, t, pose, clear)
            assert out.wheels_mmps[0] * (1 if want < 0 else -1) >= 0 >= out.wheels_mmps[1] \
                * (1 if want < 0 else -1)
        assert abs(pose[2] - want) <= task.p.bearing_tol_mrad
        assert not task.search.turning and not task.search.wandering  # a cycle at rest
        rest_from = t
        while _move(task, t + 20_000, pose, clear).wheels_mmps == (0, 0):
            t += 20_000
        # its poses looked at, then the next station
        assert task.search.turning and t - rest_from >= 3 * task.search.params.frame_period_us
        assert task.search.station_xy != station
