"""Validation of every value the host sends to the MCU: nothing invalid crosses the link.

The last check before a command is encoded: a value that is not an integer (NaN, infinity, float,
bool, None, string...) or lies outside its limit is refused with a reason, and the refusal is
counted; nothing is clamped here (clamping is the caller's policy, host/app_link.py: it coerces
with :func:`coerce_int`, clamps, and passes the result through the checks below as the last gate),
so a refused value is never sent and the caller decides what to do instead (keep the last
command, stop).

Limits: servo targets in mrad per docs/conventions.md (host/arm_calib.JOINT_LIMITS_MRAD; index 0
is the gripper closure in per mille, 0..1000), wheel speeds within ±1000 mm/s (the protocol's
SetWheels range), gripper closure 0..1000 per mille.

Module functions raise :class:`OutgoingRejected`; :class:`OutgoingGuard` wraps them, counts the
reasons and returns None instead of raising, for a control loop that must never crash.
"""

from __future__ import annotations

import math
import numbers
import operator
from collections import Counter
from collections.abc import Sequence

from mobigrasp.host.arm_calib import JOINT_LIMITS_MRAD, JOINT_NAMES, N_CHANNELS
from mobigrasp.protocol.messages import GRIPPER_CLOSED_PERMILLE, WHEEL_SPEED_LIMIT_MMPS

_LO = tuple(lo for lo, _ in JOINT_LIMITS_MRAD)  # servo target limits per channel
_HI = tuple(hi for _, hi in JOINT_LIMITS_MRAD)

# Reasons (the keys of OutgoingGuard.rejections).
NOT_A_NUMBER = "not_a_number"
NAN = "nan"
INFINITE = "infinite"
NOT_INTEGER = "not_integer"
OUT_OF_LIMITS = "out_of_limits"
WRONG_COUNT = "wrong_count"
REASONS = (NOT_A_NUMBER, NAN, INFINITE, NOT_INTEGER, OUT_OF_LIMITS, WRONG_COUNT)


class OutgoingRejected(ValueError):
    """An outgoing value was refused; ``reason`` is one of :data:`REASONS`."""

    def __init__(self, reason: str, what: str, value: object, detail: str = "") -> None:
        self.reason = reason
        self.what = what
        self.value = value
        extra = f" ({detail})" if detail else ""
        super().__init__(f"{what}: {reason}: {value!r}{extra}")


def check_int(what: str, value: object, lo: int, hi: int) -> int:
    """``value`` as a plain int if it is an integer in [lo, hi]; OutgoingRejected otherwise."""
    if type(value) is int and lo <= value <= hi:
        return value  # the usual case, decided without the (slow) numbers ABC checks below
    if isinstance(value, bool) or not isinstance(value, numbers.Number):
        raise OutgoingRejected(NOT_A_NUMBER, what, value)
    if not isinstance(value, numbers.Integral):
        try:
            f = float(value)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            raise OutgoingRejected(NOT_A_NUMBER, what, value) from None
        if math.isnan(f):
            raise OutgoingRejected(NAN, what, value)
        if math.isinf(f):
            raise OutgoingRejected(INFINITE, what, value)
        raise OutgoingRejected(NOT_INTEGER, what, value)
    v = int(value)
    if not lo <= v <= hi:
        raise OutgoingRejected(OUT_OF_LIMITS, what, value, f"limits [{lo}, {hi}]")
    return v


_COERCE_LIM = 1 << 62  # coerce_int's range: beyond any limit, within what C can hold


def coerce_int(what: str, value: object) -> int:
    """``value`` as an int, a finite non-integer number rounded to the nearest (numpy scalars
    included); OutgoingRejected for NaN, infinity, bool, None and non-numbers. The first step of
    the host's output policy (host/app_link.py): coerce, clamp to the limits, then check."""
    if type(value) is int and -_COERCE_LIM <= value <= _COERCE_LIM:
        return value  # a plain int in range passes unchanged (check_int would return it)
    try:
        return check_int(what, value, -_COERCE_LIM, _COERCE_LIM)
    except OutgoingRejected as exc:
        if exc.reason != NOT_INTEGER:
            raise
    return int(round(float(value)))  # type: ignore[arg-type]


def check_servo_mrad(targets: Sequence[object]) -> tuple[int, ...]:
    """Six servo targets (index = channel; 0 gripper per mille, 1..5 joint angles in mrad)."""
    if isinstance(targets, str | bytes) or not hasattr(targets, "__len__"):
        raise OutgoingRejected(WRONG_COUNT, "servo_mrad", targets, f"need {N_CHANNELS} values")
    if len(targets) != N_CHANNELS:
        raise OutgoingRejected(WRONG_COUNT, "servo_mrad", targets, f"need {N_CHANNELS} values")
    # the usual case: a list or tuple of six plain ints within their limits (decided without
    # formatting the names the errors below carry)
    if ((type(targets) is tuple or type(targets) is list) and set(map(type, targets)) == {int}
            and all(map(operator.le, _LO, targets)) and all(map(operator.le, targets, _HI))):
        return tuple(targets)
    return tuple(check_int(f"servo_mrad[{ch}] ({JOINT_NAMES[ch]})", targets[ch], lo, hi)
                 for ch, (lo, hi) in enumerate(JOINT_LIMITS_MRAD))


def check_wheels(left_mmps: object, right_mmps: object) -> tuple[int, int]:
    """Wheel speed targets in mm/s, each within ±1000."""
    lim = WHEEL_SPEED_LIMIT_MMPS
    return (check_int("wheels.left_mmps", left_mmps, -lim, lim),
            check_int("wheels.right_mmps", right_mmps, -lim, lim))


def check_gripper(close_permille: object) -> int:
    """Gripper closure in per mille, 0 (open) .. 1000 (closed)."""
    return check_int("gripper_permille", close_permille, 0, GRIPPER_CLOSED_PERMILLE)


class OutgoingGuard:
    """The checks with counted refusals: each method returns the checked value(s) or None."""

    def __init__(self) -> None:
        self.rejections: Counter[str] = Counter()
        self.passed = 0
        self.last_error: str | None = None

    def _run(self, fn, *args):
        try:
            out = fn(*args)
        except OutgoingRejected as exc:
            self.rejections[exc.reason] += 1
            self.last_error = str(exc)
            return None
        self.passed += 1
        return out

    def servo_mrad(self, targets: Sequence[object]) -> tuple[int, ...] | None:
        """:func:`check_servo_mrad`, or None (counted) when refused."""
        return self._run(check_servo_mrad, targets)

    def wheels(self, left_mmps: object, right_mmps: object) -> tuple[int, int] | None:
        """:func:`check_wheels`, or None (counted) when refused."""
        return self._run(check_wheels, left_mmps, right_mmps)

    def gripper(self, close_permille: object) -> int | None:
        """:func:`check_gripper`, or None (counted) when refused."""
        return self._run(check_gripper, close_permille)

    @property
    def rejected(self) -> int:
        """Total refusals."""
        return sum(self.rejections.values())

    def stats(self) -> dict:
        """Counters for the run summary."""
        return {"passed": self.passed, "rejected": self.rejected,
                "by_reason": dict(self.rejections)}
