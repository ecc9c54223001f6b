"""Differential-drive base: straight line, spin, turning radius, encoders, collisions, pushing."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host.task import REGISTRY
from mobigrasp.mcu_sim.world.base import (
    FOOTPRINT_RADIUS_M,
    TICKS_PER_M,
    WHEEL_TRACK_M,
    DiffDriveBase,
    new_space,
)
from mobigrasp.mcu_sim.world.scenario import loads_scenario
from mobigrasp.mcu_sim.world.world import World

MIN_SCENARIO = """
[scenario]
name = "t"
method = "000"
seed = 1
time_limit_s = 60
[robot]
x_m = 0
y_m = 0
heading_rad = {heading}
[target]
kind = "radial-symbol"
x_m = {tx}
y_m = {ty}
heading_rad = 0
{extra}
"""


def make_world(heading=0.0, tx=20.0, ty=20.0, extra="", **kw):
    text = MIN_SCENARIO.format(heading=heading, tx=tx, ty=ty, extra=extra)
    return World(loads_scenario(text, "test.toml", methods=REGISTRY), **kw)


def wheels_at_speed(base, vl, vr):
    """Skip the motor lag: start the motors at their commanded speeds (tests the chassis only)."""
    base.left.max_speed_mps = base.right.max_speed_mps = 1.0
    base.set_duty(round(vl * 255), round(vr * 255))
    base.left.speed_mps = base.left.target_speed_mps()
    base.right.speed_mps = base.right.target_speed_mps()
    return base.left.speed_mps, base.right.speed_mps


@pytest.mark.parametrize("heading", [0.0, 0.7, -2.5])
def test_drive_straight_distance_is_v_times_t_within_one_percent(heading):
    base = DiffDriveBase(new_space(), 1.0, -2.0, heading)
    vl, vr = wheels_at_speed(base, 0.3, 0.3)
    base.run_steps(4000)  # T = 4 s
    x, y, h = base.pose()
    dist = math.hypot(x - 1.0, y + 2.0)
    assert dist == pytest.approx(vl * 4.0, rel=0.01)
    assert h == pytest.approx(heading, abs=1e-9)
    # moved along the heading, not sideways
    assert math.atan2(y + 2.0, x - 1.0) == pytest.approx(heading, abs=1e-6)
    left, right = base.encoder_ticks()
    assert left == right
    # 1024 counts per revolution of a 40 mm wheel (docs/conventions.md)
    assert left == pytest.approx(dist / (2 * math.pi * 0.040) * 1024, abs=1)


def test_world_duty_drive_includes_the_motor_lag():
    w = make_world()
    w.set_wheel_duty(153, 153)  # 153/255 * 0.5 = 0.3 m/s
    w.step_to(3_000_000)
    v, tau, t = 0.3, 0.1, 3.0
    expect = v * (t - tau * (1 - math.exp(-t / tau)))
    assert w.truth()["base"]["x_m"] == pytest.approx(expect, rel=0.01)


def test_spin_in_place():
    base = DiffDriveBase(new_space(), 0.5, 0.5, 0.0)
    vl, vr = wheels_at_speed(base, -0.15, 0.15)
    base.run_steps(2000)
    x, y, h = base.pose()
    assert math.hypot(x - 0.5, y - 0.5) < 1e-3
    omega = (vr - vl) / WHEEL_TRACK_M
    assert h == pytest.approx(omega * 2.0, rel=0.01)
    left, right = base.encoder_ticks()
    assert left < 0 < right
    assert abs(left + right) <= 2
    assert right == pytest.approx(vr * 2.0 * TICKS_PER_M, rel=0.01)
    assert TICKS_PER_M * 2 * math.pi * 0.040 == pytest.approx(1024)


def test_turning_radius_is_respected():
    base = DiffDriveBase(new_space(), 0.0, 0.0, 0.0)
    vl, vr = wheels_at_speed(base, 0.1, 0.2)
    radius = WHEEL_TRACK_M / 2 * (vr + vl) / (vr - vl)  # 0.45 m, centre on the left
    cx, cy = 0.0, radius
    worst = 0.0
    for _ in range(60):  # 6 s, about two thirds of the 9.4 s circle
        base.run_steps(100)
        x, y, _ = base.pose()
        worst = max(worst, abs(math.hypot(x - cx, y - cy) - radius))
    assert worst < 0.01 * radius
    _, _, h = base.pose()
    assert h == pytest.approx((vr - vl) / WHEEL_TRACK_M * 6.0, rel=0.01)


BOX_AHEAD = """
[[obstacles]]
shape = "box"
x_m = 1.0
y_m = 0.0
width_m = 0.2
depth_m = 2.0
heading_rad = 0.0
"""


def test_obstacle_stops_the_base_and_the_contact_is_counted():
    w = make_world(extra=BOX_AHEAD)
    w.set_wheel_duty(255, 255)
    w.step_to(6_000_000)  # would be ~2.9 m without the box
    x, _, _ = w.base.pose()
    assert x <= 1.0 - 0.1 - FOOTPRINT_RADIUS_M + 0.005
    assert x > 0.6  # it did drive up to the box
    t = w.truth()
    assert t["collisions"]["obstacle"] == 1
    assert w.contacts.events[0].index == 0
    assert 1_000_000 < w.contacts.events[0].start_us < 3_000_000
    assert t["min_clearance_m"] < 0.005
    # encoders stop while the base is held (no counts from a blocked base)
    ticks = w.encoder_ticks()
    w.step_to(7_000_000)
    assert abs(w.encoder_ticks()[0] - ticks[0]) <= 2


def test_wall_blocks_and_clearance_is_tracked():
    extra = """
[[obstacles]]
shape = "wall"
x_m = -5.0
y_m = 0.8
x2_m = 5.0
y2_m = 0.8
"""
    w = make_world(heading=math.pi / 2, extra=extra)
    w.step_to(100_000)
    assert w.truth()["min_clearance_m"] == pytest.approx(0.8 - 0.025 - FOOTPRINT_RADIUS_M,
                                                         abs=1e-6)
    w.set_wheel_duty(200, 200)
    w.step_to(5_000_000)
    _, y, _ = w.base.pose()
    assert y < 0.8 - 0.025 - FOOTPRINT_RADIUS_M + 0.005
    assert w.contacts.count("obstacle") >= 1


def test_base_pushes_the_target_and_counts_the_contact():
    w = make_world(tx=1.0, ty=0.0)
    w.set_wheel_duty(100, 100)
    w.step_to(8_000_000)
    t = w.truth()
    assert t["collisions"]["target"] >= 1
    assert t["object"]["x_m"] > 1.2  # it was pushed ahead
    assert t["base"]["x_m"] > 1.0 - 0.2  # the base kept going (the object is light)


def test_bad_inputs_are_rejected_not_crashing():
    w = make_world()
    with pytest.raises(TypeError):
        w.step_to(1.5)
    w.step_to(10_000)
    with pytest.raises(ValueError, match="backwards"):
        w.step_to(5_000)
    w.set_wheel_duty(1e9, "x")
    assert w.base.left.rejected == 1 and w.base.right.rejected == 1
    with pytest.raises(ValueError, match="channel"):
        w.set_servo_pulse_us(7, 1500)


@examples(20, derandomize=True)
@given(approach=st.floats(-1.2, 1.2), r_obs=st.floats(0.02, 0.3), duty=st.integers(60, 255),
       turn=st.integers(-40, 40))
def test_base_never_passes_through_a_circle_obstacle(approach, r_obs, duty, turn):
    # the obstacle stands 1 m ahead; the base comes at it from any angle, at any speed
    extra = f"""
[[obstacles]]
shape = "circle"
x_m = 1.0
y_m = 0.0
radius_m = {r_obs}
"""
    w = make_world(heading=0.0, extra=extra)
    w.base.body.angle = w.base.control.angle = approach * 0.2
    w.set_wheel_duty(duty - turn if duty - turn <= 255 else 255, min(duty + turn, 255))
    worst = math.inf
    for k in range(1, 301):
        w.step_to(k * 10_000)
        x, y, _ = w.base.pose()
        worst = min(worst, math.hypot(x - 1.0, y) - r_obs - FOOTPRINT_RADIUS_M)
    assert worst > -0.005  # contact, never more than a few mm of solver overlap
    hit = w.truth()["collisions"]["obstacle"] > 0
    if worst < -0.001:
        assert hit
    if worst > 0.002:
        assert not hit


def test_a_long_press_is_one_contact_episode_with_its_duration():
    w = make_world(extra=BOX_AHEAD)
    w.set_wheel_duty(255, 255)
    w.step_to(6_000_000)
    t = w.truth()
    ep = w.contacts.events
    assert t["collisions"]["obstacle"] == 1 and len(ep) == 1 and ep[0].end_us is None
    # pressed from its start to now
    assert t["contact_time_s"]["obstacle"] == pytest.approx((6_000_000 - ep[0].start_us) / 1e6)
    assert t["contact_time_s"]["obstacle"] > 2.0


def test_touches_apart_are_two_episodes_and_a_quick_retouch_is_one():
    w = make_world(extra=BOX_AHEAD)
    w.set_wheel_duty(200, 200)
    w.step_to(5_000_000)
    w.set_wheel_duty(-200, -200)  # back off for 1 s: the episode ends
    w.step_to(6_000_000)
    first = w.contacts.events[0]
    assert first.end_us is not None and w.truth()["contact_time_s"]["obstacle"] > 0.5
    w.set_wheel_duty(200, 200)
    w.step_to(9_000_000)
    assert w.contacts.count("obstacle") == 2  # more than EPISODE_GAP_US apart
    w.set_wheel_duty(-200, -200)  # a touch broken for ~0.1 s continues its episode
    w.step_to(9_040_000)
    w.set_wheel_duty(200, 200)
    w.step_to(10_000_000)
    assert w.contacts.count("obstacle") == 2
    assert w.contacts.events[-1].end_us is None


def test_a_slide_along_a_wall_is_one_episode():
    extra = """
[[obstacles]]
shape = "wall"
x_m = 0.0
y_m = 0.30
x2_m = 3.0
y2_m = 0.30
thickness_m = 0.05
"""
    w = make_world(heading=0.25, extra=extra)
    w.set_wheel_duty(170, 180)  # into the wall at a shallow angle, then along it
    w.step_to(12_000_000)
    x, _, _ = w.base.pose()
    assert x > 0.8  # it went on along the wall
    assert w.contacts.count("obstacle") == 1
    assert w.truth()["contact_time_s"]["obstacle"] > 1.0
