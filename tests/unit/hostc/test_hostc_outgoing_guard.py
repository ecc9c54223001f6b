"""The C host's outgoing guard (hostc/outgoing_guard.c) against host/outgoing_guard.py on
integer values: the same verdicts and the same counts."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.host.outgoing_guard import OutgoingGuard

FFI, C = hostc.lib()
VALUES = st.integers(-4000, 4000)


@examples(300)
@given(st.lists(st.tuples(st.sampled_from(["servo", "wheels", "gripper"]),
                          st.lists(VALUES, min_size=6, max_size=6)), min_size=1, max_size=30))
def test_guard_verdicts_and_counts(calls):
    py = OutgoingGuard()
    c = FFI.new("mg_outgoing_guard_t *")
    C.mg_guard_init(c)
    for kind, v in calls:
        if kind == "servo":
            assert bool(C.mg_guard_servo_mrad(c, v)) == (py.servo_mrad(v) is not None)
        elif kind == "wheels":
            assert bool(C.mg_guard_wheels(c, v[0], v[1])) == (py.wheels(v[0], v[1]) is not None)
        else:
            assert bool(C.mg_guard_gripper(c, v[0])) == (py.gripper(v[0]) is not None)
        assert c.passed == py.passed
        assert c.out_of_limits == py.rejections["out_of_limits"] == py.rejected
