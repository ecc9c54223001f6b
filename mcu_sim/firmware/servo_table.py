"""Servo calibration of docs/conventions.md in integer form, and the slewed servo bank.

Servo law (conventions.md, "The arm"): ``pulse_us = pulse0_us + direction x theta x K`` with
``K = 2000 / pi`` µs/rad, i.e. 0.63662 µs per mrad, computed here as ``theta_mrad x 20000 / 31416``
(error below 0.006 µs over ±3142 mrad, and the product fits an int32). Channel 0 is the gripper:
0..1000 per mille closed maps to 1000..2000 µs. Default pulse limits come from the joint limits of
the same table, rounded inwards and clamped to 500..2500 µs; they are PARAMs at run time.

Each channel keeps three values in Q8 µs (int32 in C): ``latched`` (the width in force this
20 ms period), ``pending`` (the value written to OCRnx, latched at the next BOTTOM) and ``target``.
Slew limiting moves ``pending`` from ``latched`` towards ``target`` by at most
``slew_us_per_s / 50`` µs per period, and every value written is clamped to the channel limits,
so an out-of-limit pulse can never reach a servo, even right after a limit PARAM changed.
"""

from __future__ import annotations

SERVO_COUNT = 6
PULSE_MIN_US = 500
PULSE_MAX_US = 2500
K_NUM = 20000  # µs per mrad = K_NUM / K_DEN = 2000 / (1000 pi)
K_DEN = 31416
PERIODS_PER_S = 50  # Timer1/3 TOP = 39999 at 0.5 µs: 20 ms
GRIPPER_OPEN_US = 1000
GRIPPER_CLOSED_US = 2000

# (pulse at 0 rad or 0 per mille, direction, joint lower limit, upper limit) in mrad (per mille
# for the gripper): the arm table of docs/conventions.md.
JOINT_TABLE = (
    (GRIPPER_OPEN_US, 1, 0, 1000),
    (1500, 1, -1571, 1571),
    (2455, 1, -3000, 0),
    (2455, 1, -2800, 0),
    (545, 1, 0, 3000),
    (1500, 1, -1400, 1400),
)
# Power-on pose: gripper open, every joint at the 1500 µs centre of its servo.
HOME_US = (GRIPPER_OPEN_US, 1500, 1500, 1500, 1500, 1500)


def _div_round(num: int, den: int) -> int:
    """Integer num / den rounded to nearest, halves away from zero (den > 0)."""
    if num >= 0:
        return (num + den // 2) // den
    return -((-num + den // 2) // den)


def mrad_to_us(ch: int, value: int) -> int:
    """Pulse width in µs for joint angle ``value`` mrad on channel ``ch`` (per mille for ch 0)."""
    pulse0, direction, _, _ = JOINT_TABLE[ch]
    if ch == 0:
        return pulse0 + value  # 1000 per mille spans the 1000 µs of the gripper servo
    return pulse0 + direction * _div_round(value * K_NUM, K_DEN)


def default_limits_us(ch: int) -> tuple[int, int]:
    """(min, max) pulse in µs allowed on channel ``ch``: joint limits rounded inwards."""
    pulse0, direction, lo, hi = JOINT_TABLE[ch]
    if ch == 0:
        return pulse0 + lo, pulse0 + hi
    base = pulse0 * K_DEN
    ends = sorted((base + direction * lo * K_NUM, base + direction * hi * K_NUM))
    lo_us = -((-ends[0]) // K_DEN)  # ceil
    hi_us = ends[1] // K_DEN  # floor
    return max(PULSE_MIN_US, lo_us), min(PULSE_MAX_US, hi_us)


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
