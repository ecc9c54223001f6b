"""The one joint table (protocol/joints.py): the host calibration, the firmware servo table and
the world's servo models are each derived from it, and its integer law is the real law
``K = 2000/pi us/rad`` correctly rounded."""

import math
from fractions import Fraction

import pytest

from mobigrasp.host import arm_calib
from mobigrasp.mcu_sim.faults import safety
from mobigrasp.mcu_sim.firmware import servo_table
from mobigrasp.mcu_sim.world import actuators
from mobigrasp.protocol import joints

# pi to 40 digits: far more than the 1e-10 needed to round every int16 x 2/pi correctly
PI = Fraction("3.141592653589793238462643383279502884197")


def _round_half_away(x: Fraction) -> int:
    q = math.floor(abs(x) + Fraction(1, 2))
    return q if x >= 0 else -q


def test_integer_law_is_the_real_law_correctly_rounded_for_every_int16_angle():
    k = 2 / PI  # us per mrad
    for a in range(-32768, 32768, 7):
        assert joints.div_round(a * joints.K_NUM, joints.K_DEN) == _round_half_away(a * k), a


def test_inverse_law_is_correctly_rounded_for_every_pulse():
    k = 2 / PI
    for ch in range(1, joints.N_CHANNELS):
        p0 = joints.JOINTS[ch].pulse0_us
        for p in range(joints.PULSE_MIN_US, joints.PULSE_MAX_US + 1):
            assert joints.angle_of_pulse(ch, p) == _round_half_away((p - p0) / k), (ch, p)


def test_products_fit_int32():
    assert 32768 * joints.K_NUM < 2**31
    assert (joints.PULSE_MAX_US - joints.PULSE_MIN_US) * joints.K_DEN < 2**31


def test_mechanical_limits_are_the_joint_limits_rounded_inwards():
    k = 2000 / PI  # us per rad
    for j, (lo_us, hi_us) in zip(joints.JOINTS, joints.MECH_LIMITS_US, strict=True):
        if j.channel == 0:
            assert (lo_us, hi_us) == (1000, 2000)
            continue
        ends = sorted((j.pulse0_us + j.direction * Fraction(j.lo, 1000) * k,
                       j.pulse0_us + j.direction * Fraction(j.hi, 1000) * k))
        assert lo_us == max(500, math.ceil(ends[0]))
        assert hi_us == min(2500, math.floor(ends[1]))
    assert joints.MECH_LIMITS_US[2] == (546, 2455)


def test_host_calibration_is_derived_from_the_table():
    for j in joints.JOINTS:
        ch = j.channel
        assert arm_calib.JOINT_LIMITS_MRAD[ch] == (j.lo, j.hi)
        assert arm_calib.PULSE0_US[ch] == j.pulse0_us
        assert arm_calib.DIRECTION[ch] == j.direction
        assert arm_calib.JOINT_NAMES[ch] == j.name
        for a in range(j.lo, j.hi + 1):
            p = arm_calib.mrad_to_pulse_us(ch, a)
            assert p == min(max(joints.pulse_us(ch, a), 500), 2500)
        for p in range(500, 2501):
            assert arm_calib.pulse_us_to_mrad(ch, p) == min(max(
                joints.angle_of_pulse(ch, p), j.lo), j.hi)


def test_firmware_servo_table_is_derived_from_the_table():
    assert servo_table.SERVO_COUNT == joints.N_CHANNELS
    for j in joints.JOINTS:
        ch = j.channel
        assert servo_table.default_limits_us(ch) == joints.MECH_LIMITS_US[ch]
        for a in range(-4000, 4001):
            assert servo_table.mrad_to_us(ch, a) == joints.pulse_us(ch, a)
    assert servo_table.GRIPPER_OPEN_US == joints.JOINTS[0].pulse0_us
    assert servo_table.GRIPPER_CLOSED_US == 2000


def test_world_servo_models_are_derived_from_the_table():
    for j in joints.JOINTS:
        cal = actuators.JOINT_TABLE[j.channel]
        assert cal.pulse0_us == j.pulse0_us and cal.direction == j.direction
        assert (cal.min_rad, cal.max_rad) == (j.lo / 1000, j.hi / 1000)
        if j.channel == 0:
            continue
        # the world's float law and the integer law give the same whole microsecond
        for a in range(j.lo, j.hi + 1, 3):
            assert actuators.pulse_for_angle(j.channel, a / 1000) == min(
                max(joints.pulse_us(j.channel, a), 500), 2500)
            # and the commanded angle of an integer pulse rounds to the integer inverse
            p = joints.pulse_us(j.channel, a)
            if 500 <= p <= 2500:
                world = actuators.angle_for_pulse(j.channel, p)
                assert round(world * 1000) == pytest.approx(
                    min(max(joints.angle_of_pulse(j.channel, p), j.lo), j.hi), abs=0)


def test_safety_monitor_reads_the_table():
    for j in joints.JOINTS:
        lo, hi = safety.joint_pulse_range_us(j.channel)
        mlo, mhi = joints.MECH_LIMITS_US[j.channel]
        # the monitor allows 1 us of rounding around the real limits, which contain the
        # firmware's inward-rounded ones
        assert lo <= mlo and mhi <= hi and mlo - lo <= 2 and hi - mhi <= 2
