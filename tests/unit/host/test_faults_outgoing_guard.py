"""host/outgoing_guard: no NaN, infinity, non-integer or out-of-limit value passes."""

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host import outgoing_guard as g
from mobigrasp.host.arm_calib import JOINT_LIMITS_MRAD
from mobigrasp.protocol.messages import Gripper, SetServos, SetWheels

anything = (st.integers(-10**6, 10**6) | st.floats(allow_nan=True, allow_infinity=True)
            | st.none() | st.booleans() | st.text(max_size=3)
            | st.sampled_from([math.nan, math.inf, -math.inf, np.float32("nan"), np.int16(5),
                               np.float64(3.0), Fraction(1, 2), 1 + 2j, [1], b"\x01"]))


def _valid_int(value, lo, hi):
    return (isinstance(value, int | np.integer) and not isinstance(value, bool)
            and lo <= int(value) <= hi)


@examples(100)
@given(st.lists(anything, min_size=0, max_size=8))
def test_nothing_invalid_passes_servo_targets(values):
    guard = g.OutgoingGuard()
    out = guard.servo_mrad(values)
    ok = len(values) == 6 and all(_valid_int(v, lo, hi)
                                  for v, (lo, hi) in zip(values, JOINT_LIMITS_MRAD, strict=False))
    if ok:
        assert out == tuple(int(v) for v in values) and all(type(v) is int for v in out)
        SetServos(mode=1, targets=out, slew=0)  # and the protocol accepts what passed
        assert guard.stats() == {"passed": 1, "rejected": 0, "by_reason": {}}
    else:
        assert out is None and guard.rejected == 1 and guard.passed == 0
        assert set(guard.rejections) <= set(g.REASONS)


@examples(100)
@given(anything, anything)
def test_nothing_invalid_passes_wheels(left, right):
    guard = g.OutgoingGuard()
    out = guard.wheels(left, right)
    if _valid_int(left, -1000, 1000) and _valid_int(right, -1000, 1000):
        assert out == (int(left), int(right))
        SetWheels(left_mmps=out[0], right_mmps=out[1])
    else:
        assert out is None and guard.rejected == 1


@examples(100)
@given(anything)
def test_nothing_invalid_passes_gripper(value):
    guard = g.OutgoingGuard()
    out = guard.gripper(value)
    if _valid_int(value, 0, 1000):
        assert out == int(value)
        Gripper(close_permille=out)
    else:
        assert out is None and guard.rejected == 1


@pytest.mark.parametrize("value, reason", [
    (math.nan, g.NAN), (np.float32("nan"), g.NAN), (math.inf, g.INFINITE),
    (-math.inf, g.INFINITE), (2.5, g.NOT_INTEGER), (3.0, g.NOT_INTEGER),
    (None, g.NOT_A_NUMBER), (True, g.NOT_A_NUMBER), ("5", g.NOT_A_NUMBER),
    (1001, g.OUT_OF_LIMITS), (-1, g.OUT_OF_LIMITS),
])
def test_reasons_are_named_and_counted(value, reason):
    with pytest.raises(g.OutgoingRejected) as e:
        g.check_gripper(value)
    assert e.value.reason == reason and "gripper_permille" in str(e.value)
    guard = g.OutgoingGuard()
    assert guard.gripper(value) is None and guard.rejections[reason] == 1
    assert guard.last_error == str(e.value)


def test_servo_limits_are_the_joint_table():
    inside = [hi for _, hi in JOINT_LIMITS_MRAD]
    assert g.check_servo_mrad(inside) == tuple(inside)
    for ch, (lo, _) in enumerate(JOINT_LIMITS_MRAD):
        bad = list(inside)
        bad[ch] = lo - 1
        with pytest.raises(g.OutgoingRejected, match=rf"servo_mrad\[{ch}\].*out_of_limits"):
            g.check_servo_mrad(bad)
    with pytest.raises(g.OutgoingRejected, match="wrong_count"):
        g.check_servo_mrad(inside[:5])
    with pytest.raises(g.OutgoingRejected, match="wrong_count"):
        g.check_servo_mrad("123456")


def test_coerce_rounds_finite_numbers_and_refuses_the_rest():
    assert g.coerce_int("x", 2.6) == 3 and g.coerce_int("x", np.float32(-2.4)) == -2
    assert g.coerce_int("x", np.int16(7)) == 7 and type(g.coerce_int("x", np.int16(7))) is int
    for bad, reason in ((math.nan, g.NAN), (-math.inf, g.INFINITE), ("3", g.NOT_A_NUMBER),
                        (True, g.NOT_A_NUMBER), (None, g.NOT_A_NUMBER)):
        with pytest.raises(g.OutgoingRejected) as exc:
            g.coerce_int("x", bad)
        assert exc.value.reason == reason


@examples(100)
@given(anything, anything)
def test_the_host_link_sends_only_valid_wheel_commands(left, right):
    """The host's real send path (host/app_link.py) uses the guard: whatever the control code
    produces, what is encoded is a SetWheels within ±1000 mm/s, or nothing (counted)."""
    from mobigrasp.host.app_link import HostLink
    from mobigrasp.protocol.frame import FrameParser
    from mobigrasp.protocol.messages import decode_frame

    link = HostLink()
    sent = link.send_wheels(left, right, at_us=0)
    frames = [decode_frame(f) for _, data in link.take_output(1) for f in FrameParser().feed(data)]
    if sent:
        (msg,) = frames
        assert isinstance(msg, SetWheels)
        assert -1000 <= msg.left_mmps <= 1000 and -1000 <= msg.right_mmps <= 1000
    else:
        assert frames == [] and link.counters.rejected_outputs == 1
