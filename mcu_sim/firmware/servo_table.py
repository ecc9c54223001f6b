"""Servo calibration of docs/conventions.md in integer form, and the slewed servo bank.

Servo law and limits: the joint table of ``protocol/joints.py`` (docs/conventions.md, "The
arm"): ``pulse_us = pulse0_us + direction x theta_mrad x K_NUM / K_DEN`` rounded, with
``K_NUM / K_DEN = 33215 / 52174`` us per mrad (2/pi correctly rounded for every int16 angle; the
product fits an int32). Channel 0 is the gripper: 0..1000 per mille closed maps to 1000..2000 us.
The mechanical limits (``joints.MECH_LIMITS_US``: joint limits rounded inwards, within 500..2500
us) are compile-time constants; the limit PARAMs may only narrow them (docs/firmware.md).

Each channel keeps three values in Q8 µs (int32 in C): ``latched`` (the width in force this
20 ms period), ``pending`` (the value written to OCRnx, latched at the next BOTTOM) and ``target``.
Slew limiting moves ``pending`` from ``latched`` towards ``target`` by at most
``slew_us_per_s / 50`` µs per period, and every value written is clamped to the channel limits,
so an out-of-limit pulse can never reach a servo, even right after a limit PARAM changed.
"""

from __future__ import annotations

from mobigrasp.protocol import joints

SERVO_COUNT = joints.N_CHANNELS
PULSE_MIN_US = joints.PULSE_MIN_US
PULSE_MAX_US = joints.PULSE_MAX_US
K_NUM = joints.K_NUM
K_DEN = joints.K_DEN
PERIODS_PER_S = 50  # Timer1/3 TOP = 39999 at 0.5 µs: 20 ms
GRIPPER_OPEN_US = joints.JOINTS[0].pulse0_us
GRIPPER_CLOSED_US = GRIPPER_OPEN_US + joints.JOINTS[0].hi
MECH_MIN_US = tuple(lo for lo, _ in joints.MECH_LIMITS_US)  # const uint16_t[6] in flash
MECH_MAX_US = tuple(hi for _, hi in joints.MECH_LIMITS_US)
# Power-on pose: gripper open, every joint at the 1500 µs centre of its servo.
HOME_US = (GRIPPER_OPEN_US, 1500, 1500, 1500, 1500, 1500)
_div_round = joints.div_round


def mrad_to_us(ch: int, value: int) -> int:
    """Pulse width in µs for joint angle ``value`` mrad on channel ``ch`` (per mille for ch 0)."""
    return joints.pulse_us(ch, value)


def default_limits_us(ch: int) -> tuple[int, int]:
    """(min, max) pulse in µs allowed on channel ``ch``: the mechanical limits."""
    return joints.MECH_LIMITS_US[ch]


def slew_step_q8(slew_us_per_s: int) -> int:
    """Largest change per 20 ms period in Q8 µs for a slew rate in µs/s (0 = unlimited)."""
    if slew_us_per_s <= 0:
        return 0
    return max(1, (slew_us_per_s << 8) // PERIODS_PER_S)


def mrad_slew_to_us(slew_mrad_per_s: int) -> int:
    """Convert a slew rate in mrad/s into µs/s (rounded, at least 1 when non-zero)."""
    if slew_mrad_per_s <= 0:
        return 0
    return max(1, _div_round(slew_mrad_per_s * K_NUM, K_DEN))


class ServoBank:
    """The six channels' latched / pending / target widths (Q8 µs), limits and slew steps."""

    def __init__(self) -> None:
        self.latched_q8 = [0] * SERVO_COUNT
        self.pending_q8 = [0] * SERVO_COUNT
        self.target_q8 = [0] * SERVO_COUNT
        self.step_q8 = [0] * SERVO_COUNT
        self.min_us = [0] * SERVO_COUNT
        self.max_us = [0] * SERVO_COUNT
        self.reset()

    def reset(self) -> None:
        """Power-on: home pose, default limits, no slew limit."""
        for ch in range(SERVO_COUNT):
            self.min_us[ch], self.max_us[ch] = default_limits_us(ch)
            home = HOME_US[ch] << 8
            self.latched_q8[ch] = self.pending_q8[ch] = self.target_q8[ch] = home
            self.step_q8[ch] = 0

    def set_target_us(self, ch: int, pulse_us: int, slew_us_per_s: int) -> bool:
        """Aim channel ``ch`` at ``pulse_us`` clamped to its limits; True if it had to clamp."""
        clamped = min(max(pulse_us, self.min_us[ch]), self.max_us[ch])
        self.target_q8[ch] = clamped << 8
        self.step_q8[ch] = slew_step_q8(slew_us_per_s)
        return clamped != pulse_us

    def hold(self) -> None:
        """Stop every channel where it is now (targets = latched widths)."""
        for ch in range(SERVO_COUNT):
            self.target_q8[ch] = self.latched_q8[ch]

    def next_pending(self, ch: int) -> int:
        """Recompute ``pending`` one slew step from ``latched`` towards ``target``; clamp; return
        the OCR value for it (timer ticks of 0.5 µs minus one)."""
        latched = self.latched_q8[ch]
        delta = self.target_q8[ch] - latched
        step = self.step_q8[ch]
        if step and delta > step:
            delta = step
        elif step and delta < -step:
            delta = -step
        value = latched + delta
        lo = self.min_us[ch] << 8
        hi = self.max_us[ch] << 8
        value = lo if value < lo else hi if value > hi else value
        self.pending_q8[ch] = value
        return ((value + 64) >> 7) - 1

    def latch(self) -> None:
        """Timer BOTTOM: the pending widths are now in force."""
        self.latched_q8[:] = self.pending_q8  # in place: the same list, all six copied

    def latched_us(self, ch: int) -> int:
        """Width in force on ``ch``, rounded to whole µs (for telemetry)."""
        return (self.latched_q8[ch] + 128) >> 8
