"""Path update of 001 §III.E: blocked detection and replanning from the present state."""

import math

import numpy as np
import pytest
from region_ref import Ref, grown_m

from mobigrasp.host.planning.bezier import Curve, evaluate
from mobigrasp.host.planning.replan import Replanner

CLEAR = [2500] * 5


def state_on(curve, t_s):
    tau = curve.tau_at_time(curve.ctrl[0][2] + t_s)
    x, y, _ = curve.point(tau)
    d = evaluate(curve.array, np.array([tau]))
    return (x, y), float(d.heading[0]), (float(d.speed[0] * math.cos(d.heading[0])),
                                         float(d.speed[0] * math.sin(d.heading[0])))


def test_clear_sonar_keeps_the_path():
    rp = Replanner((3.0, 1.0))
    plan = rp.start(0, (0.0, 0.0), 0.0, (0.2, 0.0), CLEAR)
    assert plan.best is not None
    pos, hd, vel = state_on(rp.curve, 2.0)
    dec = rp.update(2_000_000, pos, hd, vel, CLEAR)
    assert not dec.blocked and not dec.replanned and dec.curve is plan.best
    assert dec.ops.cycles() == 0  # nothing to test against


def test_forced_update_plans_from_here_although_the_path_is_clear():
    # the caller stopped following the path (the sonar guard stopped the base): a plan is
    # asked for, and "path clear" with no new curve would leave the base standing
    rp = Replanner((3.0, 1.0))
    plan = rp.start(0, (0.0, 0.0), 0.0, (0.2, 0.0), CLEAR)
    pos, hd, _ = state_on(rp.curve, 2.0)
    dec = rp.update(2_000_000, pos, hd, (0.0, 0.0), CLEAR, force=True)
    assert dec.replanned and dec.curve is not None and dec.curve is not plan.best
    assert not dec.blocked and dec.reason == "path dropped: replanned"
    assert np.allclose(dec.curve.ctrl[0][:2], pos, atol=1 / 16000)  # in 1/16 mm


def test_obstacle_on_the_path_triggers_a_replan_from_the_present_state():
    rp = Replanner((4.0, 1.0))
    rp.start(0, (0.0, 0.0), 0.0, (0.2, 0.0), CLEAR)
    old = rp.curve
    pos, hd, vel = state_on(old, 3.0)
    sonar = [2500, 2500, 1500, 2500, 2500]  # something 1.5 m straight ahead
    dec = rp.update(3_000_000, pos, hd, vel, sonar)
    assert dec.blocked and dec.replanned
    assert rp.replans == 1
    new = dec.curve
    assert new is not old and rp.curve is new and rp.start_us == 3_000_000
    assert np.allclose(np.asarray(new.ctrl[0][:2]), pos, atol=1 / 16000)  # where the robot is
    s = new.sample(200)
    assert abs(s.heading[0] - hd) < 2e-4  # and keeps its direction of motion (Q14)
    assert dec.plan.extra["regions"]
    for reg in dec.plan.extra["regions"]:
        assert not Ref(grown_m(reg, -0.003)).contains(s.x[1:], s.y[1:]).any()
    assert 0 < dec.ops.time_us() <= 100_000
    # later, the sonars see that place clear: the remembered region is forgotten, no block
    again = rp.update(3_500_000, *state_on(new, 0.5), CLEAR)
    assert not again.blocked and not again.replanned and again.ops.cycles() > 0


def test_blocked_without_a_feasible_path_says_stop():
    rp = Replanner((4.0, 0.0))
    rp.start(0, (0.0, 0.0), 0.0, (0.2, 0.0), CLEAR)
    pos, hd, vel = state_on(rp.curve, 3.0)
    dec = rp.update(3_000_000, pos, hd, vel, [2500, 2500, 900, 2500, 2500])
    assert dec.blocked and not dec.replanned
    assert dec.curve is None and rp.curve is None and "no feasible" in dec.reason


def test_obstacle_beside_the_path_does_not_trigger():
    rp = Replanner((4.0, 0.0))
    rp.start(0, (0.0, 0.0), 0.0, (0.2, 0.0), CLEAR)
    pos, hd, vel = state_on(rp.curve, 2.0)
    dec = rp.update(2_000_000, pos, hd, vel, [2500, 2500, 2500, 2500, 600])  # left side
    assert not dec.blocked and not dec.replanned
    assert dec.ops.cycles() > 0


def test_remembered_region_still_blocks_after_it_leaves_the_sonar_view():
    rp = Replanner((4.0, 0.0))
    rp.start(0, (0.0, 0.0), 0.0, (0.2, 0.0), [2500, 2500, 1500, 2500, 2500])
    assert len(rp.memory) >= 1
    reg = rp.memory[0]
    # a curve that goes straight through the remembered region is reported blocked
    rp.curve = Curve(((0, 0, 0), (1, 0, 5), (2, 0, 10), (3, 0, 15)))
    rp.start_us = 0
    blocked, _ = rp.remaining_blocked(0, [reg])
    assert blocked


def test_no_path_makes_the_next_plan_slower():
    target = (3.267732437050385, 0.0)
    sonar = [2500, 2500, 1200, 1050, 2500]  # echoes ahead and ahead-left
    rp = Replanner(target)
    first = rp.start(0, (0.0, 0.0), 0.0, (0.0, 0.0), sonar)
    assert first.best is None and rp.v0_mps == 0.1  # v0 = 0.2 found nothing
    dec = rp.update(100_000, (0.0, 0.0), 0.0, (0.0, 0.0), sonar)
    assert dec.replanned and dec.curve is not None
    assert dec.curve.duration_s == pytest.approx(math.hypot(*target) / 0.1, abs=1e-3)  # eq. (7)
    assert len(rp.memory) == len(set(rp.memory))  # the same echoes are remembered once


def test_remembered_regions_are_forgotten_once_the_sonars_see_their_place_again():
    """A region stays in memory only while its place is out of the sonars' view."""
    rp = Replanner((4.0, 1.0))
    rp.start(0, (0.0, 0.0), 0.0, (0.2, 0.0), [2500, 2500, 1500, 2500, 2500])
    assert len(rp.memory) == 1  # 1.5 m ahead, the S_3-only sub-region
    # turned away by pi: the place is behind the ring's span, so it is kept
    assert rp.forget_seen((0.0, 0.0), math.pi) == 0 and len(rp.memory) == 1
    # farther than D_e: kept
    assert rp.forget_seen((-1.5, 0.0), 0.0) == 0 and len(rp.memory) == 1
    # facing it within D_e: the fresh reading describes that place now
    assert rp.forget_seen((0.5, 0.0), 0.0) == 1 and len(rp.memory) == 0


def test_blocked_far_ahead_without_an_update_keeps_the_path_and_near_stops():
    """No feasible update: the path is kept while the block is beyond keep_going_m."""
    from dataclasses import replace

    rp = Replanner((4.0, 0.0), keep_going_m=1.2)
    rp.start(0, (0.0, 0.0), 0.0, (0.2, 0.0), CLEAR)
    old = rp.curve
    rp.params = replace(rp.params, a_max=1e-6)  # no curve can bend now: every update fails
    pos, hd, vel = state_on(old, 1.0)
    far = rp.update(1_000_000, pos, hd, vel, [2500, 2500, 2000, 2500, 2500])
    assert far.blocked and not far.replanned and far.curve is old and rp.curve is old
    assert "path kept" in far.reason and rp.start_us == 0  # the old timing goes on
    near = rp.update(1_300_000, *state_on(old, 1.3), [2500, 2500, 700, 2500, 2500])
    assert near.blocked and near.curve is None and rp.curve is None
