"""Actuator models driven by the MCU outputs: hobby servos (arm, gripper) and DC wheel motors.

These are the plant side of the joint table (docs/conventions.md). Inputs arrive in integer
microseconds (pulse widths, time stamps, step lengths); the physics inside is float (this is the
plant, not MCU code).

Servo calibration is the joint table of protocol/joints.py (docs/conventions.md "The arm"), in
float as the physical law: for joints 1..5 ``pulse_us = pulse0_us + direction * theta * K``
with ``K = 2000/pi`` us/rad exactly, pulses clamped to [500, 2500] us and angles to the joint
limits (the table's mrad / 1000). Channel 0 is the gripper: 1000 us = open (60 mm),
2000 us = closed (0 mm); its state is the closure fraction 0..1 (theta0 in the table).

Servo motion is a pure rate limit (about 60 deg per 0.17 s, a common analogue hobby servo at
4.8-6 V) towards the commanded angle; the servo "holds under load" because position is never
disturbed by the world (the arm is light and the servo stiff). The position is evaluated in
closed form at any time, so the world does not have to step six servos at 1 kHz.

The DC motor maps a signed duty -255..255 to a wheel surface speed through a gearbox with
saturation (0.5 m/s at full duty at 12 V) and a first-order lag (tau = 0.1 s), integrated exactly
over each step: ``v <- v_t + (v - v_t) * exp(-dt/tau)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mobigrasp.protocol import joints

SERVO_K_US_PER_RAD = 2000.0 / math.pi
"""Servo gain K: 500..2500 us spans pi rad (docs/conventions.md)."""
PULSE_MIN_US = joints.PULSE_MIN_US
PULSE_MAX_US = joints.PULSE_MAX_US
SERVO_SPEED_RAD_PER_S = (math.pi / 3.0) / 0.17
"""60 degrees per 0.17 s, the no-load speed of a standard hobby servo."""

GRIPPER_OPEN_US = joints.JOINTS[0].pulse0_us
GRIPPER_CLOSED_US = GRIPPER_OPEN_US + joints.JOINTS[0].hi
GRIPPER_MAX_OPENING_M = 0.060

MOTOR_MAX_SPEED_MPS = 0.5
"""Wheel surface speed at duty 255 and the nominal supply."""
MOTOR_NOMINAL_SUPPLY_V = 12.0
MOTOR_TAU_S = 0.1
DUTY_MAX = 255


@dataclass(frozen=True)
class JointCalibration:
    """One row of the arm table: pulse at 0 rad, direction and angle limits of a joint."""

    channel: int
    pulse0_us: float
    direction: int
    min_rad: float
    max_rad: float


# Limits in rad from the table's mrad; on ch 0 (the gripper) per mille becomes the closure
# fraction 0 (open) .. 1 (closed).
JOINT_TABLE: tuple[JointCalibration, ...] = tuple(
    JointCalibration(j.channel, float(j.pulse0_us), j.direction, j.lo / 1000, j.hi / 1000)
    for j in joints.JOINTS)
N_CHANNELS = len(JOINT_TABLE)


def clamp_pulse_us(pulse_us: float) -> float:
    """Clamp a pulse width to the [500, 2500] us servo range."""
    return min(max(float(pulse_us), PULSE_MIN_US), PULSE_MAX_US)


def angle_for_pulse(ch: int, pulse_us: float) -> float:
    """Joint state commanded by a pulse on channel ``ch`` (rad; gripper: closure fraction 0..1)."""
    cal = _calibration(ch)
    p = clamp_pulse_us(pulse_us)
    if ch == 0:
        value = (p - GRIPPER_OPEN_US) / (GRIPPER_CLOSED_US - GRIPPER_OPEN_US)
    else:
        value = (p - cal.pulse0_us) / (cal.direction * SERVO_K_US_PER_RAD)
    return min(max(value, cal.min_rad), cal.max_rad)


def pulse_for_angle(ch: int, value: float) -> int:
    """Inverse of :func:`angle_for_pulse` rounded to whole microseconds (clamped to the limits)."""
    cal = _calibration(ch)
    v = min(max(float(value), cal.min_rad), cal.max_rad)
    if ch == 0:
        p = GRIPPER_OPEN_US + v * (GRIPPER_CLOSED_US - GRIPPER_OPEN_US)
    else:
        p = cal.pulse0_us + cal.direction * v * SERVO_K_US_PER_RAD
    return int(round(clamp_pulse_us(p)))


def _calibration(ch: int) -> JointCalibration:
    if not isinstance(ch, int) or not 0 <= ch < N_CHANNELS:
        raise ValueError(f"servo channel must be an int 0..{N_CHANNELS - 1}, got {ch!r}")
    return JOINT_TABLE[ch]


class Servo:
    """A rate-limited position servo on one channel, evaluated in closed form.

    ``set_pulse_us(pulse_us, t_us)`` retargets the servo at time ``t_us``; ``angle_at(t_us)``
    gives its position at any later time. Times must not go backwards.
    """

    def __init__(self, ch: int, initial: float, speed_rad_per_s: float = SERVO_SPEED_RAD_PER_S):
        self.cal = _calibration(ch)
        self.ch = ch
        self._start = min(max(float(initial), self.cal.min_rad), self.cal.max_rad)
        self._target = self._start
        self._t0_us = 0
        if ch == 0:
            # The gripper horn turns pi/2 rad for the full 1000 us stroke: same horn speed.
            speed = speed_rad_per_s * SERVO_K_US_PER_RAD / (GRIPPER_CLOSED_US - GRIPPER_OPEN_US)
        else:
            speed = speed_rad_per_s
        self._rate_per_us = speed * 1e-6
        self.pulse_us = pulse_for_angle(ch, self._start)
        self.rejected = 0

    @property
    def target(self) -> float:
        """Commanded joint state (after clamping)."""
        return self._target

    def set_pulse_us(self, pulse_us: float, t_us: int) -> None:
        """Command a pulse width from time ``t_us``; non-finite pulses are counted and dropped."""
        if not isinstance(pulse_us, (int, float)) or not math.isfinite(pulse_us):
            self.rejected += 1
            return
        target = angle_for_pulse(self.ch, pulse_us)
        if target == self._target:
            return
        self._start = self.angle_at(t_us)
        self._t0_us = int(t_us)
        self._target = target
        self.pulse_us = clamp_pulse_us(pulse_us)

    def angle_at(self, t_us: int) -> float:
        """Joint state at ``t_us``: moves at the rate limit from the last retarget, then holds."""
        if t_us < self._t0_us:
            raise ValueError(f"servo {self.ch}: time went backwards ({t_us} < {self._t0_us} us)")
        step = (t_us - self._t0_us) * self._rate_per_us
        diff = self._target - self._start
        if abs(diff) <= step:
            return self._target
        return self._start + math.copysign(step, diff)


def gripper_opening_m(closure: float) -> float:
    """Finger opening (m) for a closure fraction 0 (open, 60 mm) .. 1 (closed, 0 mm)."""
    return GRIPPER_MAX_OPENING_M * (1.0 - min(max(closure, 0.0), 1.0))


class DcMotor:
    """Geared DC wheel motor: signed duty -> wheel surface speed with lag and saturation.

    Fault hooks (for the reliability work): ``stuck`` (wheel locked, speed forced to 0) and
    ``gain`` (a weak motor or low battery scales the reachable speed).
    """

    def __init__(self, max_speed_mps: float = MOTOR_MAX_SPEED_MPS, tau_s: float = MOTOR_TAU_S,
                 supply_v: float = MOTOR_NOMINAL_SUPPLY_V):
        if tau_s <= 0 or max_speed_mps <= 0:
            raise ValueError("DcMotor: tau_s and max_speed_mps must be positive")
        self.max_speed_mps = max_speed_mps
        self._decay_cache: dict[int, float] = {}
        self.tau_s = tau_s
        self.supply_v = supply_v
        self.duty = 0
        self.speed_mps = 0.0
        self.stuck = False
        self.gain = 1.0
        self.rejected = 0

    @property
    def tau_s(self) -> float:
        """Time constant of the lag (s)."""
        return self._tau_s

    @tau_s.setter
    def tau_s(self, value: float) -> None:
        # a new time constant makes every cached exp(-dt/tau) wrong
        if not value > 0:
            raise ValueError(f"DcMotor: tau_s must be positive, got {value!r}")
        self._tau_s = value
        self._decay_cache.clear()

    def set_duty(self, duty: int) -> None:
        """Command a duty in -255..255 (clamped); a non-integer duty is counted and dropped."""
        if isinstance(duty, bool) or not isinstance(duty, int):
            self.rejected += 1
            return
        self.duty = min(max(duty, -DUTY_MAX), DUTY_MAX)

    def target_speed_mps(self) -> float:
        """Steady-state wheel surface speed for the present duty (0 when stuck)."""
        if self.stuck:
            return 0.0
        scale = self.gain * self.supply_v / MOTOR_NOMINAL_SUPPLY_V
        return self.max_speed_mps * scale * self.duty / DUTY_MAX

    def decay(self, dt_us: int) -> float:
        """exp(-dt/tau) for a step of ``dt_us`` (cached; the world uses one fixed step)."""
        d = self._decay_cache.get(dt_us)
        if d is None:
            d = math.exp(-dt_us * 1e-6 / self.tau_s)
            self._decay_cache[dt_us] = d
        return d

    def advance(self, dt_us: int) -> float:
        """Integrate the first-order lag exactly over ``dt_us``; returns the new speed (m/s)."""
        if dt_us < 0:
            raise ValueError(f"DcMotor.advance: negative step {dt_us} us")
        target = self.target_speed_mps()
        if self.stuck:
            self.speed_mps = 0.0
        else:
            self.speed_mps = target + (self.speed_mps - target) * self.decay(dt_us)
        return self.speed_mps
