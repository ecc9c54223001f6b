"""The arm's joint table of docs/conventions.md: channels, limits and the servo law, integer only.

The host needs its own copy of the table (the MCU firmware has one for the real board) to turn
telemetry pulse widths back into joint angles and to keep every command inside the limits.

Servo law (all joints but the gripper, docs/conventions.md "The arm"):
``pulse_us = pulse0_us + direction * theta * K`` with ``K = 2000/pi us/rad`` (500..2500 us spans
pi rad).  With angles in mrad, ``K = 2/pi us/mrad``; we use the rational ``2_000_000 / 3_141_593``
(error < 1e-7 relative) and round half away from zero, so the mapping is symmetric about 0.

The table's ``pulse at 0 rad`` column is used as printed (2455 us for theta2 and theta3, 545 us
for theta4).  Note: its remark "theta = -pi/2 <-> 1500" does not follow from 2455 and K (that
gives -1.5 rad <-> 1500 us); the printed column wins here and the mismatch is reported.

Channel 0 is the gripper: its "angle" is the closure in per mille (0 = open 60 mm -> 1000 us,
1000 = closed -> 2000 us).
"""

from __future__ import annotations

GRIPPER_CH = 0
N_CHANNELS = 6

PULSE_MIN_US = 500
PULSE_MAX_US = 2500

# K = 2/pi us per mrad as a rational number.
_K_NUM = 2_000_000
_K_DEN = 3_141_593

# Joint limits in mrad (docs/conventions.md, rad x 1000 rounded); ch 0 in per mille of closure.
JOINT_LIMITS_MRAD: tuple[tuple[int, int], ...] = (
    (0, 1000),        # 0 gripper closure, per mille
    (-1571, 1571),    # 1 theta1 wrist roll, [-pi/2, pi/2]
    (-3000, 0),       # 2 theta2 wrist pitch
    (-2800, 0),       # 3 theta3 elbow pitch
    (0, 3000),        # 4 theta4 shoulder pitch
    (-1400, 1400),    # 5 theta5 waist yaw
)

# Pulse width at angle 0 and direction, per channel (docs/conventions.md table).
PULSE0_US: tuple[int, ...] = (1000, 1500, 2455, 2455, 545, 1500)
DIRECTION: tuple[int, ...] = (1, 1, 1, 1, 1, 1)

JOINT_NAMES: tuple[str, ...] = (
    "gripper", "wrist_roll", "wrist_pitch", "elbow_pitch", "shoulder_pitch", "waist_yaw")


def _check_ch(ch: int) -> None:
    if not isinstance(ch, int) or isinstance(ch, bool) or not 0 <= ch < N_CHANNELS:
        raise ValueError(f"servo channel must be an int in 0..{N_CHANNELS - 1}, got {ch!r}")


def _check_int(name: str, value: int) -> None:
    if not isinstance(value, int) or isinstance(value, bool):
        raise ValueError(f"{name} must be an int, got {value!r}")


def _div_round(num: int, den: int) -> int:
    """num/den rounded half away from zero (den > 0)."""
    q = (abs(num) * 2 + den) // (2 * den)
    return q if num >= 0 else -q


def clamp_mrad(ch: int, angle_mrad: int) -> int:
    """Clamp an angle (or the gripper closure in per mille on ch 0) to the joint limits."""
    if type(ch) is int and type(angle_mrad) is int and 0 <= ch < N_CHANNELS:  # the usual call
        lo, hi = JOINT_LIMITS_MRAD[ch]
        return min(max(angle_mrad, lo), hi)
    _check_ch(ch)
    _check_int("angle_mrad", angle_mrad)
    lo, hi = JOINT_LIMITS_MRAD[ch]
    return min(max(angle_mrad, lo), hi)


def within_limits(ch: int, angle_mrad: int) -> bool:
    """True if the angle lies inside the joint limits of channel ``ch``."""
    _check_ch(ch)
    lo, hi = JOINT_LIMITS_MRAD[ch]
    return lo <= angle_mrad <= hi


def _clamp_pulse(pulse_us: int) -> int:
    return min(max(pulse_us, PULSE_MIN_US), PULSE_MAX_US)


def mrad_to_pulse_us(ch: int, angle_mrad: int) -> int:
    """Pulse width for a joint angle: the servo law, angle first clamped to the joint limits.

    On the gripper channel the argument is the closure in per mille (0 open .. 1000 closed).
    The result always lies in [500, 2500] us.
    """
    angle = clamp_mrad(ch, angle_mrad)
    if ch == GRIPPER_CH:
        return _clamp_pulse(PULSE0_US[0] + angle)   # 1 us per per-mille: 1000..2000 us
    delta = _div_round(DIRECTION[ch] * angle * _K_NUM, _K_DEN)
    return _clamp_pulse(PULSE0_US[ch] + delta)


def pulse_us_to_mrad(ch: int, pulse_us: int) -> int:
    """Joint angle for a telemetry pulse width (inverse servo law), clamped to the limits.

    A pulse outside [500, 2500] us is bad telemetry: ValueError naming the channel.
    """
    _check_ch(ch)
    _check_int("pulse_us", pulse_us)
    if not PULSE_MIN_US <= pulse_us <= PULSE_MAX_US:
        raise ValueError(
            f"channel {ch} ({JOINT_NAMES[ch]}): pulse {pulse_us} us outside "
            f"[{PULSE_MIN_US}, {PULSE_MAX_US}] us")
    if ch == GRIPPER_CH:
        return clamp_mrad(ch, pulse_us - PULSE0_US[0])
    angle = _div_round(DIRECTION[ch] * (pulse_us - PULSE0_US[ch]) * _K_DEN, _K_NUM)
    return clamp_mrad(ch, angle)


def pulses_to_joints_mrad(pulses_us: tuple[int, ...] | list[int]) -> tuple[int, ...]:
    """All six telemetry pulses to joint angles (index = channel)."""
    if len(pulses_us) != N_CHANNELS:
        raise ValueError(f"need {N_CHANNELS} pulses, got {len(pulses_us)}")
    # the same telemetry is converted several times per control step (inputs, detectors):
    # remember the answers for tuples of plain ints (host speed only; bad pulses still raise).
    # Looked up before the int check: a key equal to a remembered one (1500.0 == 1500) gives
    # the same angles as computed below (int() of each), and only good pulses are remembered.
    if type(pulses_us) is tuple:
        try:
            hit = _JOINTS_SEEN.get(pulses_us)
        except TypeError:  # an unhashable element: converted (or refused) below
            hit = None
        if hit is not None:
            return hit
    cacheable = type(pulses_us) is tuple and all(type(p) is int for p in pulses_us)
    # a new combination (the arm moving) mostly repeats single-channel pulses seen before
    out_list = []
    for ch, p in enumerate(pulses_us):
        p = int(p)
        seen = _ANGLE_SEEN[ch]
        angle = seen.get(p)
        if angle is None:
            angle = pulse_us_to_mrad(ch, p)  # a bad pulse raises here and is not remembered
            seen[p] = angle  # at most 2001 good pulses per channel
        out_list.append(angle)
    out = tuple(out_list)
    if cacheable:
        if len(_JOINTS_SEEN) >= 512:
            _JOINTS_SEEN.clear()
        _JOINTS_SEEN[pulses_us] = out
    return out


_JOINTS_SEEN: dict[tuple[int, ...], tuple[int, ...]] = {}
_ANGLE_SEEN: tuple[dict[int, int], ...] = tuple({} for _ in range(N_CHANNELS))  # per channel


def joints_to_pulses_us(angles_mrad: tuple[int, ...] | list[int]) -> tuple[int, ...]:
    """All six joint targets (index = channel; ch 0 closure per mille) to pulse widths."""
    if len(angles_mrad) != N_CHANNELS:
        raise ValueError(f"need {N_CHANNELS} joint angles, got {len(angles_mrad)}")
    return tuple(mrad_to_pulse_us(ch, a) for ch, a in enumerate(angles_mrad))


def clamp_joints_mrad(angles_mrad: tuple[int, ...] | list[int]) -> tuple[int, ...]:
    """Clamp all six joint targets to their limits."""
    if len(angles_mrad) != N_CHANNELS:
        raise ValueError(f"need {N_CHANNELS} joint angles, got {len(angles_mrad)}")
    if set(map(type, angles_mrad)) == _INT_ONLY:  # the usual call: clamp_mrad's short path,
        # min(max(a, lo), hi) per channel, in C (map) as it runs at every control step
        return tuple(map(min, map(max, angles_mrad, _LO_MRAD), _HI_MRAD))
    return tuple(clamp_mrad(ch, a) for ch, a in enumerate(angles_mrad))


_INT_ONLY = {int}  # set(map(type, values)) of plain ints (bool is not int)
_LO_MRAD = tuple(lo for lo, _ in JOINT_LIMITS_MRAD)
_HI_MRAD = tuple(hi for _, hi in JOINT_LIMITS_MRAD)
