"""Servo and DC motor models (docs/conventions.md): calibration table, rate limit, lag,
saturation."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.mcu_sim.world.actuators import (
    JOINT_TABLE,
    SERVO_SPEED_RAD_PER_S,
    DcMotor,
    Servo,
    angle_for_pulse,
    gripper_opening_m,
    pulse_for_angle,
)


def test_conventions_table_reference_points():
    # docs/conventions.md pulse0 column as printed (2455, 545) with K = 2000/pi: 1500 us is
    # 955 us = 1.5 rad from zero (the table's "-pi/2 <-> 1500" remark does not follow from it;
    # host/arm_calib.py reads the table the same way).
    assert angle_for_pulse(2, 2455) == 0.0
    assert angle_for_pulse(4, 545) == 0.0
    assert angle_for_pulse(2, 1500) == pytest.approx(-1.5, abs=1e-3)
    assert angle_for_pulse(3, 1500) == pytest.approx(-1.5, abs=1e-3)
    assert angle_for_pulse(4, 1500) == pytest.approx(1.5, abs=1e-3)
    assert angle_for_pulse(1, 1500) == 0.0
    assert angle_for_pulse(5, 1500) == 0.0
    assert gripper_opening_m(angle_for_pulse(0, 1000)) == pytest.approx(0.060)
    assert gripper_opening_m(angle_for_pulse(0, 2000)) == pytest.approx(0.0)
    assert gripper_opening_m(angle_for_pulse(0, 1500)) == pytest.approx(0.030)


@examples(150)
@given(ch=st.integers(0, 5), pulse=st.floats(-1e6, 1e6, allow_nan=False))
def test_any_pulse_gives_an_angle_within_the_joint_limits(ch, pulse):
    cal = JOINT_TABLE[ch]
    a = angle_for_pulse(ch, pulse)
    assert cal.min_rad <= a <= cal.max_rad


@examples(150)
@given(ch=st.integers(1, 5), frac=st.floats(0.0, 1.0))
def test_pulse_angle_round_trip_within_one_microsecond(ch, frac):
    cal = JOINT_TABLE[ch]
    theta = cal.min_rad + frac * (cal.max_rad - cal.min_rad)
    p = pulse_for_angle(ch, theta)
    assert 500 <= p <= 2500
    back = angle_for_pulse(ch, p)
    # inside the 500..2500 us range the round trip is exact to one microsecond of pulse
    k = 2000 / math.pi
    expect = min(max(theta, (500 - cal.pulse0_us) / k), (2500 - cal.pulse0_us) / k)
    assert abs(back - expect) <= 1.0 / k + 1e-12


def test_servo_moves_at_the_rate_limit_then_holds():
    s = Servo(5, 0.0)
    s.set_pulse_us(pulse_for_angle(5, math.pi / 3), t_us=1_000_000)
    assert s.angle_at(1_000_000) == 0.0
    # 60 degrees take about 0.17 s
    assert s.angle_at(1_085_000) == pytest.approx(SERVO_SPEED_RAD_PER_S * 0.085, rel=1e-9)
    assert s.angle_at(1_085_000) < math.pi / 3
    assert s.angle_at(1_171_000) == pytest.approx(math.pi / 3, abs=1e-3)
    assert s.angle_at(5_000_000) == pytest.approx(math.pi / 3, abs=1e-3)
    # retarget mid-way: continues from where it is, no jump
    s.set_pulse_us(pulse_for_angle(5, 0.0), t_us=5_000_000)
    s.set_pulse_us(pulse_for_angle(5, 1.0), t_us=5_050_000)
    mid = s.angle_at(5_050_000)
    assert mid == pytest.approx(math.pi / 3 - SERVO_SPEED_RAD_PER_S * 0.05, abs=1e-3)
    with pytest.raises(ValueError):
        s.angle_at(4_000_000)


def test_servo_drops_non_finite_pulses_and_rejects_bad_channels():
    s = Servo(3, -1.0)
    s.set_pulse_us(float("nan"), 0)
    s.set_pulse_us(float("inf"), 0)
    assert s.rejected == 2
    assert s.angle_at(10_000) == -1.0
    with pytest.raises(ValueError, match="channel"):
        Servo(6, 0.0)


def test_gripper_closes_in_about_a_quarter_second():
    g = Servo(0, 0.0)
    g.set_pulse_us(2000, 0)
    assert 0.0 < g.angle_at(100_000) < 1.0
    assert g.angle_at(300_000) == 1.0


def test_dc_motor_first_order_lag_matches_the_analytic_step_response():
    m = DcMotor()
    m.set_duty(255)
    v = 0.0
    for _ in range(100):  # 0.1 s in 1 ms steps
        v = m.advance(1000)
    assert v == pytest.approx(0.5 * (1 - math.exp(-1.0)), rel=1e-9)
    for _ in range(900):
        v = m.advance(1000)
    assert v == pytest.approx(0.5, rel=1e-4)


def test_dc_motor_time_constant_change_takes_effect_at_once():
    m = DcMotor()
    assert m.decay(1000) == pytest.approx(math.exp(-1e-3 / m.tau_s))  # now cached
    m.tau_s = 0.5
    assert m.decay(1000) == pytest.approx(math.exp(-1e-3 / 0.5))  # not the cached old one
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="tau_s"):
            m.tau_s = bad
    assert m.tau_s == 0.5


def test_dc_motor_saturates_and_clamps_duty_and_counts_garbage():
    m = DcMotor()
    m.set_duty(10_000)
    assert m.duty == 255
    m.set_duty(-10_000)
    assert m.duty == -255
    assert m.target_speed_mps() == pytest.approx(-0.5)
    m.set_duty(1.5)
    m.set_duty(True)
    assert m.rejected == 2 and m.duty == -255
    m.supply_v = 6.0
    assert m.target_speed_mps() == pytest.approx(-0.25)


def test_dc_motor_stuck_fault_locks_the_wheel():
    m = DcMotor()
    m.set_duty(200)
    m.advance(500_000)
    assert m.speed_mps > 0.3
    m.stuck = True
    assert m.advance(1000) == 0.0
    m.stuck = False
    assert 0.0 < m.advance(1000) < 0.01
