"""Property tests of host.fixedpoint against float references, with the stated maximum errors."""
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host import fixedpoint as fp

ANGLES = st.integers(min_value=-50_000, max_value=50_000)


@examples(200)
@given(ANGLES)
def test_sin_cos_within_one_lsb(a):
    assert abs(fp.sin_q12(a) - 4096 * math.sin(a / 1000)) <= 1.0
    assert abs(fp.cos_q12(a) - 4096 * math.cos(a / 1000)) <= 1.0


def test_sin_cos_exhaustive_one_turn():
    worst = 0.0
    for a in range(-3200, 3200):
        worst = max(worst, abs(fp.sin_q12(a) - 4096 * math.sin(a / 1000)),
                    abs(fp.cos_q12(a) - 4096 * math.cos(a / 1000)))
    assert worst <= 1.0
    assert fp.sin_q12(0) == 0 and fp.cos_q12(0) == 4096
    assert fp.sin_q12(1571) == 4096 and fp.sin_q12(-1571) == -4096


@examples(300)
@given(st.integers(-(2**32) + 1, 2**32 - 1))
def test_sin_cos_of_microradians_in_q14(a):
    """sincos_urad_q14: within 2 LSB of Q14 over its whole range (the table's interpolation
    and the 2^-20 turn rounding)."""
    s, c = fp.sincos_urad_q14(a)
    assert abs(s - 16384 * math.sin(a / 1e6)) <= 2.0
    assert abs(c - 16384 * math.cos(a / 1e6)) <= 2.0


@examples(200)
@given(st.integers(-10**6, 10**6), st.integers(-10**6, 10**6))
def test_atan2_within_one_mrad(y, x):
    got = fp.atan2_mrad(y, x)
    if x == 0 and y == 0:
        assert got == 0
        return
    ref = 1000 * math.atan2(y, x)
    err = abs(got - ref)
    err = min(err, abs(err - 2000 * math.pi))  # +pi and -pi are the same direction
    assert err <= 1.0  # 1 mrad = 0.057 deg, under the detectors' 0.1 deg bearing target
    assert -3142 <= got <= 3142


def test_atan2_small_vectors_and_axes():
    worst = 0.0
    for y in range(-40, 41):
        for x in range(-40, 41):
            if x or y:
                err = abs(fp.atan2_urad(y, x) - 1e6 * math.atan2(y, x))
                err = min(err, abs(err - 2e6 * math.pi))
                worst = max(worst, err)
    assert worst < 20
    assert fp.atan2_mrad(0, 5) == 0
    assert fp.atan2_mrad(5, 0) == 1571
    assert fp.atan2_mrad(-5, 0) == -1571
    assert abs(fp.atan2_mrad(0, -5)) == 3142


@examples(200)
@given(st.integers(0, 2**64))
def test_isqrt_exact_floor(n):
    r = fp.isqrt(n)
    assert r * r <= n < (r + 1) * (r + 1)
    assert r == math.isqrt(n)


def test_isqrt_small_and_negative():
    assert [fp.isqrt(n) for n in range(10)] == [0, 1, 1, 1, 2, 2, 2, 2, 2, 3]
    with pytest.raises(ValueError):
        fp.isqrt(-1)


@examples(100)
@given(st.integers(-2**20, 2**20), st.integers(-2**20, 2**20))
def test_mul_q12_rounds(a, b):
    assert abs(fp.mul_q12(a, b) - a * b / 4096) <= 0.5


@examples(100)
@given(st.integers(-10**7, 10**7), st.integers(-10**4, 10**4).filter(lambda d: d != 0))
def test_div_round(n, d):
    assert abs(fp.div_round(n, d) - n / d) <= 0.5


def test_div_by_zero_is_clear():
    with pytest.raises(ValueError, match="zero"):
        fp.div_round(3, 0)


def _float_rot(axis, a):
    c, s = math.cos(a), math.sin(a)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


@examples(100)
@given(st.sampled_from("xyz"), st.integers(-3142, 3142),
       st.lists(st.integers(-5000, 5000), min_size=3, max_size=3))
def test_rotation_matvec_against_float(axis, a, v):
    m = {"x": fp.rot_x_q12, "y": fp.rot_y_q12, "z": fp.rot_z_q12}[axis](a)
    ref = _float_rot(axis, a / 1000) @ np.array(v, float)
    got = np.array(fp.matvec_q12(m, v))
    # 1 LSB per entry over |v| <= 8660 -> at most ~2.2 units, plus 0.5 rounding
    assert np.max(np.abs(got - ref)) <= 3.0


@examples(100)
@given(st.integers(-3142, 3142), st.integers(-3142, 3142))
def test_matmul_and_transpose(a, b):
    m = fp.matmul_q12(fp.rot_z_q12(a), fp.rot_x_q12(b))
    ref = _float_rot("z", a / 1000) @ _float_rot("x", b / 1000)
    assert np.max(np.abs(np.array(m) / 4096 - ref)) <= 3 / 4096
    ident = np.array(fp.matmul_q12(m, fp.transpose_q12(m)))
    assert np.max(np.abs(ident - 4096 * np.eye(3))) <= 4


def test_matvec_bad_shape():
    with pytest.raises(ValueError):
        fp.matvec_q12(fp.IDENTITY_Q12, (1, 2))


def test_op_counts_cost_something():
    assert fp.sin_ops().cycles() > 0
    assert fp.atan2_ops().divs >= 1
    assert fp.isqrt_ops(2**30).cycles() > fp.isqrt_ops(100).cycles()
