"""The arm's joint table: channel, joint, pulse law and mechanical limits (docs/conventions.md).

The one source of the table. The host calibration (host/arm_calib.py), the firmware servo table
(mcu_sim/firmware/servo_table.py) and the world's servo models (mcu_sim/world/actuators.py) are
derived from it; it lives in ``protocol`` because both boards may import protocol and nothing
else in common. Stdlib only, integers only: the C ports hold the same rows as ``const`` data.

Servo law (channels 1..5): ``pulse_us = pulse0_us + direction * theta * K`` with
``K = 2000/pi us/rad`` (500..2500 us spans pi rad). In integer form ``K = K_NUM / K_DEN`` us per
mrad with ``K_NUM / K_DEN = 33215 / 52174``, a convergent of 2/pi: for every int16 angle in mrad
the rounded pulse, and for every pulse in 500..2500 us the rounded angle, equal the correctly
rounded real law (tests/unit/protocol/test_joint_table.py checks both), and the products fit an
int32 (32768 x 33215 and 2500 x 52174 are below 2^31). Channel 0 is the gripper: its "angle" is the
closure in per mille (0 open = 1000 us .. 1000 closed = 2000 us), 1 us per per mille.

Mechanical limits: the joint limits of the table as pulse widths, rounded inwards and clamped to
500..2500 us (:data:`MECH_LIMITS_US`). The firmware never drives a pulse outside them, whatever
any PARAM says (docs/firmware.md "Safety limits").
"""

from __future__ import annotations

from typing import NamedTuple

PULSE_MIN_US = 500
PULSE_MAX_US = 2500
K_NUM = 33215  # us per mrad = K_NUM / K_DEN = 2 / pi (correctly rounded, see above)
K_DEN = 52174
GRIPPER_CH = 0


class Joint(NamedTuple):
    """One row: the joint on ``channel``, its pulse at angle 0 and limits (mrad; gripper per
    mille of closure)."""

    channel: int
    name: str
    pulse0_us: int
    direction: int
    lo: int
    hi: int


JOINTS: tuple[Joint, ...] = (
    Joint(0, "gripper", 1000, 1, 0, 1000),               # closure per mille, 1000 us = open
    Joint(1, "wrist_roll", 1500, 1, -1571, 1571),        # theta1, [-pi/2, pi/2]
    Joint(2, "wrist_pitch", 2455, 1, -3000, 0),          # theta2
    Joint(3, "elbow_pitch", 2455, 1, -2800, 0),          # theta3
    Joint(4, "shoulder_pitch", 545, 1, 0, 3000),         # theta4
    Joint(5, "waist_yaw", 1500, 1, -1400, 1400),         # theta5
)
N_CHANNELS = len(JOINTS)


def div_round(num: int, den: int) -> int:
    """``num / den`` rounded to nearest, halves away from zero (den > 0); C: integer division
    of ``2 * |num| + den`` by ``2 * den``, sign restored."""
    q = (abs(num) * 2 + den) // (2 * den)
    return q if num >= 0 else -q


def pulse_us(ch: int, value: int) -> int:
    """Pulse width of the law for ``value`` mrad on channel ``ch`` (per mille on the gripper);
    not clamped."""
    j = JOINTS[ch]
    if ch == GRIPPER_CH:
        return j.pulse0_us + value
    return j.pulse0_us + j.direction * div_round(value * K_NUM, K_DEN)


def angle_of_pulse(ch: int, pulse: int) -> int:
    """Inverse law: angle in mrad (gripper: per mille) for ``pulse`` us; not clamped."""
    j = JOINTS[ch]
    if ch == GRIPPER_CH:
        return pulse - j.pulse0_us
    return j.direction * div_round((pulse - j.pulse0_us) * K_DEN, K_NUM)


def _mech_limits_us(ch: int) -> tuple[int, int]:
    j = JOINTS[ch]
    if ch == GRIPPER_CH:
        a, b = j.pulse0_us + j.lo, j.pulse0_us + j.hi
        return max(PULSE_MIN_US, min(a, b)), min(PULSE_MAX_US, max(a, b))
    base = j.pulse0_us * K_DEN
    ends = sorted((base + j.direction * j.lo * K_NUM, base + j.direction * j.hi * K_NUM))
    lo_us = -((-ends[0]) // K_DEN)  # ceil: inwards
    hi_us = ends[1] // K_DEN  # floor: inwards
    return max(PULSE_MIN_US, lo_us), min(PULSE_MAX_US, hi_us)


MECH_LIMITS_US: tuple[tuple[int, int], ...] = tuple(_mech_limits_us(ch) for ch in range(N_CHANNELS))
"""(min, max) pulse in us each channel may ever get: compile-time constants of the firmware."""
