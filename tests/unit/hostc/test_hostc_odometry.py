"""The C host's odometry (hostc/odometry.c) against host/odometry.py: the same telemetry
sequence (clock, cumulative int32 encoder counters, wrapping, resets and MCU restarts) gives the
same pose after every sample and the same count of dropped samples."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.host import odometry

FFI, C = hostc.lib()

# one event: a telemetry sample (dt_us, ticks left, ticks right) -- dt may be negative (from the
# past) and a jump may be impossible (dropped) -- or a reset to a pose, or an MCU restart
SAMPLE = st.tuples(st.just("sample"), st.integers(-30_000, 200_000),
                   st.integers(-400, 400) | st.integers(-(1 << 33), 1 << 33),
                   st.integers(-400, 400))
RESET = st.tuples(st.just("reset"), st.integers(-(1 << 34), 1 << 34),
                  st.integers(-(1 << 34), 1 << 34), st.integers(-20_000, 20_000))
RESYNC = st.tuples(st.just("resync"), st.just(0), st.just(0), st.just(0))
EVENTS = st.lists(SAMPLE | RESET | RESYNC, min_size=20, max_size=120)


def _pose(p) -> tuple[int, ...]:
    return (p.x_um, p.y_um, p.heading_mrad, p.speed_mm_s, p.yaw_rate_mrad_s)


def _wrap(v: int) -> int:
    return ((v + (1 << 31)) & 0xFFFFFFFF) - (1 << 31)


@examples(120)
@given(st.integers(-(1 << 34), 1 << 34), st.integers(-(1 << 34), 1 << 34),
       st.integers(-3142, 3142), st.integers(-(1 << 31), (1 << 31) - 1),
       st.integers(-(1 << 31), (1 << 31) - 1), EVENTS)
def test_odometry_sequence(x_um, y_um, heading, enc_l0, enc_r0, events):
    py = odometry.Odometry(x_um, y_um, heading)
    c = FFI.new("mg_odometry_t *")
    C.mg_odometry_init(c, x_um, y_um, heading)
    t_us, enc_l, enc_r = 1_000_000, enc_l0, enc_r0
    for kind, a, b, d in events:
        if kind == "sample":
            t_us += a
            enc_l, enc_r = _wrap(enc_l + b), _wrap(enc_r + d)
            got = C.mg_odometry_update(c, t_us, enc_l, enc_r)
            assert _pose(got) == _pose(py.update(t_us, enc_l, enc_r))
        elif kind == "reset":
            py.reset(a, b, d)
            C.mg_odometry_reset(c, a, b, d)
        else:
            py.resync()
            C.mg_odometry_resync(c)
        assert _pose(C.mg_odometry_pose(c)) == _pose(py.pose)
        assert C.mg_odometry_heading_urad(c) == py.heading_urad
        assert c.dropped == py.dropped


def test_a_long_drive_turning_many_times():
    """Thousands of samples of a spinning base: the heading runs over many turns unwrapped and
    the accumulators grow; both stay identical."""
    py = odometry.Odometry()
    c = FFI.new("mg_odometry_t *")
    C.mg_odometry_init(c, 0, 0, 0)
    enc_l = enc_r = 0
    for k in range(20_000):
        enc_l, enc_r = _wrap(enc_l - 7 - k % 3), _wrap(enc_r + 9)
        t_us = 20_000 * k
        assert _pose(C.mg_odometry_update(c, t_us, enc_l, enc_r)) == _pose(
            py.update(t_us, enc_l, enc_r))
    assert abs(py.heading_urad) > 20 * odometry.URAD_PER_TURN
    assert C.mg_odometry_heading_urad(c) == py.heading_urad


def test_update_op_counts():
    assert hostc.ops_tuple(C.mg_odometry_update_ops()) == odometry.UPDATE_OPS.as_tuple()
