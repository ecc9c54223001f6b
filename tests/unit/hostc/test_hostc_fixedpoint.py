"""The C host's fixed point and cycle accounting (hostc/fixedpoint.c, trig.c, budget.c) against
host/fixedpoint.py and host/budget.py: same inputs, identical outputs."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.host import budget, fixedpoint

FFI, C = hostc.lib()
I64 = st.integers(-(1 << 40), 1 << 40)
ANGLES = st.integers(-12_000_000, 12_000_000)  # 2000 turns: the C's stated range
SETTINGS = examples(400)


@SETTINGS
@given(ANGLES)
def test_sin_cos(angle):
    assert (C.mg_sin_q12(angle), C.mg_cos_q12(angle)) == fixedpoint.sincos_q12(angle)


@SETTINGS
@given(st.integers(-(2**32) + 1, 2**32 - 1))
def test_sin_cos_of_microradians(angle):
    s, c = FFI.new("int32_t *"), FFI.new("int32_t *")
    C.mg_sincos_urad_q14(angle, s, c)
    assert (s[0], c[0]) == fixedpoint.sincos_urad_q14(angle)


@SETTINGS
@given(st.integers(-(1 << 61), 1 << 61), st.integers(-(1 << 61), 1 << 61))
def test_atan2_on_the_whole_64_bit_range(y, x):
    """Operands of 2^46 and more take the bit-by-bit quotient: still Python's exact ratio."""
    assert C.mg_atan2_urad(y, x) == fixedpoint.atan2_urad(y, x)
    assert C.mg_atan2_mrad(y, x) == fixedpoint.atan2_mrad(y, x)


@pytest.mark.parametrize("y, x", [((1 << 61) - 1, 1 << 61), (1 << 61, 1 << 61), (3 << 47, 1 << 49),
                                  (1, 0), (0, -5), (-(1 << 50), -(1 << 50) - 1), (0, 0)])
def test_atan2_ratio_edges(y, x):
    assert C.mg_atan2_urad(y, x) == fixedpoint.atan2_urad(y, x)


@SETTINGS
@given(st.integers(0, (1 << 62)))
def test_isqrt(n):
    assert C.mg_isqrt(n) == fixedpoint.isqrt(n) == fixedpoint.isqrt_digits(n)
    assert C.mg_isqrt(-1 - n) == -1


@SETTINGS
@given(I64, st.integers(-(1 << 40), 1 << 40).filter(lambda d: d != 0))
def test_rounded_division_of_either_sign(num, den):
    """Python's div_round rounds halves away from zero for both signs of den; so does C."""
    assert C.mg_div_round64(num, den) == fixedpoint.div_round(num, den)
    assert C.mg_floor_div(num, den) == num // den
    assert C.mg_floor_mod(num, den) == num % den
    assert C.mg_div_q12(num >> 14, den) == fixedpoint.div_q12(num >> 14, den)


@pytest.mark.parametrize("num, den", [(5, 2), (-5, 2), (5, -2), (-5, -2), (7, 7), (-1, 3)])
def test_rounded_division_halves(num, den):
    assert C.mg_div_round64(num, den) == fixedpoint.div_round(num, den)


@SETTINGS
@given(st.integers(-(1 << 30), 1 << 30), st.integers(-(1 << 30), 1 << 30))
def test_mul_q12_and_hypot(a, b):
    assert C.mg_mul_q12(a, b) == fixedpoint.mul_q12(a, b)
    assert C.mg_hypot_int(a, b) == fixedpoint.hypot_int(a, b)


def _mat(m):
    return tuple(tuple(int(m[i][j]) for j in range(3)) for i in range(3))


@SETTINGS
@given(st.integers(-7000, 7000), st.integers(-7000, 7000),
       st.lists(st.integers(-(1 << 18), 1 << 18), min_size=3, max_size=3))
def test_rotations(a, b, v):
    for c_rot, py_rot in ((C.mg_rot_x_q12, fixedpoint.rot_x_q12),
                          (C.mg_rot_y_q12, fixedpoint.rot_y_q12),
                          (C.mg_rot_z_q12, fixedpoint.rot_z_q12)):
        m = FFI.new("mg_mat_q12")
        c_rot(a, m)
        assert _mat(m) == py_rot(a)
    ma, mb, out = FFI.new("mg_mat_q12"), FFI.new("mg_mat_q12"), FFI.new("mg_mat_q12")
    C.mg_rot_x_q12(a, ma)
    C.mg_rot_z_q12(b, mb)
    C.mg_matmul_q12(ma, mb, out)
    expect = fixedpoint.matmul_q12(fixedpoint.rot_x_q12(a), fixedpoint.rot_z_q12(b))
    assert _mat(out) == expect
    C.mg_transpose_q12(out, out)
    assert _mat(out) == fixedpoint.transpose_q12(expect)
    vec = FFI.new("int32_t[3]", v)
    C.mg_matvec_q12(ma, vec, vec)
    assert tuple(vec) == fixedpoint.matvec_q12(fixedpoint.rot_x_q12(a), v)


def test_op_counts_of_the_fixed_point_calls():
    assert hostc.ops_tuple(C.mg_sin_ops()) == fixedpoint.sin_ops().as_tuple()
    assert hostc.ops_tuple(C.mg_atan2_ops()) == fixedpoint.atan2_ops().as_tuple()
    assert hostc.ops_tuple(C.mg_matvec_ops()) == fixedpoint.matvec_ops().as_tuple()
    assert hostc.ops_tuple(C.mg_rot_ops()) == fixedpoint.rot_ops().as_tuple()
    for k in (0, 1, 7):
        assert hostc.ops_tuple(C.mg_mul_q12_ops(k)) == fixedpoint.mul_q12_ops(k).as_tuple()
    for n in (0, 1, 2, 3, 255, 1 << 40, (1 << 62) + 5):
        assert hostc.ops_tuple(C.mg_isqrt_ops(n)) == fixedpoint.isqrt_ops(n).as_tuple()


COUNTS = st.lists(st.integers(0, 1 << 30), min_size=11, max_size=11)


@SETTINGS
@given(COUNTS, COUNTS, st.integers(0, 1000))
def test_cycles_and_modelled_time(a, b, k):
    """OpCounts' sum, scaling, cycles and time (rounded up, cache lines rounded up) in C."""
    ca, cb = FFI.new("mg_ops_t *", a), FFI.new("mg_ops_t *", b)
    pa, pb = budget.OpCounts(*a), budget.OpCounts(*b)
    total = FFI.new("mg_ops_t *", C.mg_ops_scaled(C.mg_ops_add(ca[0], cb[0]), k))
    expect = (pa + pb).scaled(k)
    assert hostc.ops_tuple(total[0]) == expect.as_tuple()
    assert C.mg_ops_cycles(total) == expect.cycles()
    assert C.mg_ops_time_us(total) == expect.time_us()
    assert C.mg_ops_time_us(ca) == pa.time_us()
