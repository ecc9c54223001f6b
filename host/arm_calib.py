"""The arm's joint table on the host: limits and the servo law of protocol/joints.py, integer only.

The host turns telemetry pulse widths back into joint angles and keeps every command inside the
limits. The table and the law (``K = 2000/pi us/rad`` as the rational ``33215 / 52174`` us per
mrad, correctly rounded both ways) are ``protocol.joints``, the one source the firmware and the
world read too (docs/conventions.md "The arm").

The table's ``pulse at 0 rad`` column is used as printed (2455 us for theta2 and theta3, 545 us
for theta4).  Note: its remark "theta = -pi/2 <-> 1500" does not follow from 2455 and K (that
gives -1.5 rad <-> 1500 us); the printed column wins here and the mismatch is reported.

Channel 0 is the gripper: its "angle" is the closure in per mille (0 = open 60 mm -> 1000 us,
1000 = closed -> 2000 us).
"""

from __future__ import annotations

from mobigrasp.protocol import joints

GRIPPER_CH = joints.GRIPPER_CH
N_CHANNELS = joints.N_CHANNELS

PULSE_MIN_US = joints.PULSE_MIN_US
PULSE_MAX_US = joints.PULSE_MAX_US

# Joint limits in mrad (rad x 1000 rounded); ch 0 in per mille of closure.
JOINT_LIMITS_MRAD: tuple[tuple[int, int], ...] = tuple((j.lo, j.hi) for j in joints.JOINTS)
# Pulse width at angle 0 and direction, per channel.
PULSE0_US: tuple[int, ...] = tuple(j.pulse0_us for j in joints.JOINTS)
DIRECTION: tuple[int, ...] = tuple(j.direction for j in joints.JOINTS)
JOINT_NAMES: tuple[str, ...] = tuple(j.name for j in joints.JOINTS)


def _check_ch(ch: int) -> None:
    if not isinstance(ch, int) or isinstance(ch, bool) or not 0 <= ch < N_CHANNELS:
        raise ValueError(f"servo channel must be an int in 0..{N_CHANNELS - 1}, got {ch!r}")


def _check_int(name: str, value: int) -> None:
    if not isinstance(value, int) or isinstance(value, bool):
        raise ValueError(f"{name} must be an int, got {value!r}")


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
    return _clamp_pulse(joints.pulse_us(ch, angle))


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
    return clamp_mrad(ch, joints.angle_of_pulse(ch, pulse_us))


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
