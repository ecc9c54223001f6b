"""host/arm_calib: the joint table and the servo law against a float reference."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host import arm_calib as ac

K_US_PER_RAD = 2000.0 / math.pi


def ref_pulse(ch: int, angle_mrad: int) -> float:
    lo, hi = ac.JOINT_LIMITS_MRAD[ch]
    a = min(max(angle_mrad, lo), hi)
    if ch == 0:
        return 1000 + a
    return min(max(ac.PULSE0_US[ch] + a / 1000.0 * K_US_PER_RAD, 500), 2500)


def test_table_values_from_conventions():
    assert ac.JOINT_LIMITS_MRAD[2] == (-3000, 0)
    assert ac.JOINT_LIMITS_MRAD[3] == (-2800, 0)
    assert ac.JOINT_LIMITS_MRAD[4] == (0, 3000)
    assert ac.JOINT_LIMITS_MRAD[5] == (-1400, 1400)
    assert ac.mrad_to_pulse_us(1, 0) == 1500
    assert ac.mrad_to_pulse_us(5, 0) == 1500
    assert ac.mrad_to_pulse_us(2, 0) == 2455
    assert ac.mrad_to_pulse_us(4, 0) == 545
    # pi/2 is 1000 us of travel: the roll limits land on the pulse range ends
    assert ac.mrad_to_pulse_us(1, 1571) == 2500
    assert ac.mrad_to_pulse_us(1, -1571) == 500
    # 1 rad = 636.62 us
    assert ac.mrad_to_pulse_us(5, 1000) == 2137
    assert ac.mrad_to_pulse_us(5, -1000) == 863


def test_gripper_per_mille():
    assert ac.mrad_to_pulse_us(0, 0) == 1000
    assert ac.mrad_to_pulse_us(0, 1000) == 2000
    assert ac.mrad_to_pulse_us(0, 5000) == 2000
    assert ac.pulse_us_to_mrad(0, 1500) == 500


@examples(200)
@given(ch=st.integers(0, 5), angle=st.integers(-5000, 5000))
def test_pulse_matches_float_law_and_stays_in_range(ch, angle):
    p = ac.mrad_to_pulse_us(ch, angle)
    assert 500 <= p <= 2500
    assert abs(p - ref_pulse(ch, angle)) <= 0.5 + 1e-9


@examples(200)
@given(ch=st.integers(1, 5), data=st.data())
def test_round_trip_within_one_microsecond_of_angle(ch, data):
    lo, hi = ac.JOINT_LIMITS_MRAD[ch]
    angle = data.draw(st.integers(lo, hi))
    back = ac.pulse_us_to_mrad(ch, ac.mrad_to_pulse_us(ch, angle))
    # one pulse microsecond is 1.57 mrad; rounding twice costs at most ~1 mrad
    assert abs(back - angle) <= 1
    assert lo <= back <= hi


def test_clamp_and_limits():
    assert ac.clamp_mrad(3, 100) == 0
    assert ac.clamp_mrad(3, -9999) == -2800
    assert ac.within_limits(4, 1500)
    assert not ac.within_limits(4, -1)
    assert ac.clamp_joints_mrad((2000, 0, 1, -3001, 3001, 2000)) == (1000, 0, 0, -2800, 3000, 1400)


def test_bad_input_is_a_clear_error():
    with pytest.raises(ValueError, match="channel"):
        ac.mrad_to_pulse_us(6, 0)
    with pytest.raises(ValueError, match="outside"):
        ac.pulse_us_to_mrad(2, 2600)
    with pytest.raises(ValueError, match="int"):
        ac.mrad_to_pulse_us(2, 1.5)
    with pytest.raises(ValueError, match="6"):
        ac.pulses_to_joints_mrad((1500,) * 5)


def test_telemetry_vector():
    joints = ac.pulses_to_joints_mrad((1000, 1500, 1500, 1500, 1500, 1500))
    assert joints[0] == 0 and joints[1] == 0 and joints[5] == 0
    # 2455 - 1500 = 955 us = 1.5 rad below zero for the wrist and elbow, above for the shoulder
    assert joints[2] == -1500 and joints[3] == -1500 and joints[4] == 1500
    assert ac.joints_to_pulses_us(joints) == (1000, 1500, 1500, 1500, 1500, 1500)
