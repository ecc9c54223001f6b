"""Fixed-point arithmetic for the S3C2440 (no FPU): Q12 scalars, trigonometry, isqrt, 3x3 rotations.

Formats and units (binding for every caller):

- ``q12``: signed integer with 12 fractional bits, 1.0 == ``ONE_Q12`` == 4096. A product of two
  Q12 numbers is rounded back to Q12 by :func:`mul_q12` (round half up).
- Angles are integer **milliradians** (``angle_mrad``). :func:`sin_q12` / :func:`cos_q12` accept
  any integer mrad (reduced modulo 2π exactly, not modulo 6283) and return Q12.
  Maximum error against ``round(4096 * sin(angle_mrad / 1000))``: 1 LSB (2.5e-4).
- :func:`atan2_mrad` takes two integers in any common unit and returns the angle in mrad in
  [-3142, 3142]; maximum error 1 mrad (0.057°, under the detectors' 0.1° bearing target).
  ``atan2_mrad(0, 0) == 0``.
- :func:`isqrt` is the exact floor square root (digit-by-digit, as on the ARM).
- Rotation matrices are tuples of three rows of Q12 ints; :func:`matvec_q12` multiplies one
  by an integer vector in any unit (mm, Q4 px ...) and returns the same unit, rounded.

Implementation: sine from a 1024-entry quarter-wave table in Q14 over the binary angle
(65536 per turn) with linear interpolation; atan from a 257-entry table over tan in [0, 1] in
micro-radians, octant reduction and interpolation. The tables are built once at import with
``math`` (on the board they are ``const`` arrays in flash); the runtime paths use integers only.
Op-count helpers (``*_ops``) say what each call costs on the ARM920T (host.budget).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from mobigrasp.host.budget import OpCounts

Q12_SHIFT = 12
ONE_Q12 = 1 << Q12_SHIFT
Q16_SHIFT = 16
ONE_Q16 = 1 << Q16_SHIFT

PI_MRAD = 3142  # round(1000 * pi), for limits and clamps
HALF_PI_MRAD = 1571

# --- sine / cosine ---------------------------------------------------------------------------
_BAM_BITS = 16  # binary angle: 65536 units per turn
_QUARTER_BITS = 10  # 1024 table steps per quarter turn
_FRAC_BITS = _BAM_BITS - 2 - _QUARTER_BITS  # 4 interpolation bits
_SIN_Q14 = tuple(round(16384 * math.sin(i * math.pi / 2 / 1024)) for i in range(1025))
# mrad -> binary angle scale in Q32: 65536 / (2000 pi) * 2^32 (one SMULL on the ARM).
_MRAD_TO_BAM_Q32 = round((1 << _BAM_BITS) / (2000.0 * math.pi) * (1 << 32))
_BAM_ROUND = 1 << 31


def _sin_bam_q14(bam: int) -> int:
    """Sine in Q14 of a binary angle with 4 extra fractional bits (2^20 per turn)."""
    turn = bam & ((1 << (_BAM_BITS + _FRAC_BITS)) - 1)
    quadrant = turn >> (_BAM_BITS + _FRAC_BITS - 2)
    within = turn & ((1 << (_BAM_BITS + _FRAC_BITS - 2)) - 1)
    if quadrant & 1:  # mirror the 2nd and 4th quadrants onto the first
        within = (1 << (_BAM_BITS + _FRAC_BITS - 2)) - within
    idx = within >> (_FRAC_BITS + 4)
    frac = within & ((1 << (_FRAC_BITS + 4)) - 1)
    a = _SIN_Q14[idx]
    b = _SIN_Q14[idx + 1] if idx < 1024 else a
    val = a + (((b - a) * frac + (1 << (_FRAC_BITS + 3))) >> (_FRAC_BITS + 4))
    return -val if quadrant & 2 else val


def _mrad_to_bam20(angle_mrad: int) -> int:
    # 2^20 units per turn: BAM16 with 4 fractional bits, so interpolation keeps sub-step detail.
    return (int(angle_mrad) * _MRAD_TO_BAM_Q32 * 16 + _BAM_ROUND) >> 32


def sin_q12(angle_mrad: int) -> int:
    """sin(angle_mrad / 1000) in Q12 (error <= 1 LSB)."""
    if type(angle_mrad) is int:  # remembered (host speed: the same angles recur every step)
        v = _SIN_SEEN.get(angle_mrad)
        if v is None:
            v = (_sin_bam_q14(_mrad_to_bam20(angle_mrad)) + 2) >> 2
            _remember(_SIN_SEEN, angle_mrad, v)
        return v
    return (_sin_bam_q14(_mrad_to_bam20(angle_mrad)) + 2) >> 2


def cos_q12(angle_mrad: int) -> int:
    """cos(angle_mrad / 1000) in Q12 (error <= 1 LSB)."""
    if type(angle_mrad) is int:
        v = _COS_SEEN.get(angle_mrad)
        if v is None:
            v = (_sin_bam_q14(_mrad_to_bam20(angle_mrad) + _QUARTER_BAM20) + 2) >> 2
            _remember(_COS_SEEN, angle_mrad, v)
        return v
    return (_sin_bam_q14(_mrad_to_bam20(angle_mrad) + _QUARTER_BAM20) + 2) >> 2


_QUARTER_BAM20 = 1 << (_BAM_BITS + _FRAC_BITS - 2)
_SIN_SEEN: dict[int, int] = {}
_COS_SEEN: dict[int, int] = {}


def _remember(seen: dict[int, int], key: int, value: int) -> None:
    if len(seen) >= 16384:  # bounded: angles are mostly within one turn
        seen.clear()
    seen[key] = value


def sincos_turn_q12(num: int, den: int) -> tuple[int, int]:
    """(sin, cos) in Q12 of num/den of a turn (den > 0), by the same table through a binary
    angle rounded to 2^-20 of a turn: exact at the quarter turns (sin π = 0), where an angle in
    whole mrad is not."""
    bam = div_round(int(num) << (_BAM_BITS + _FRAC_BITS), den)
    return (_sin_bam_q14(bam) + 2) >> 2, (_sin_bam_q14(bam + _QUARTER_BAM20) + 2) >> 2


def sincos_q12(angle_mrad: int) -> tuple[int, int]:
    """(sin, cos) of the same angle in Q12."""
    return sin_q12(angle_mrad), cos_q12(angle_mrad)


# urad -> 2^-20 turn in Q32: 2^20 / (2e6 pi) * 2^32 (one 64-bit multiply on the ARM)
URAD_TO_BAM20_Q32 = round((1 << (_BAM_BITS + _FRAC_BITS)) / (2e6 * math.pi) * (1 << 32))


def sincos_urad_q14(angle_urad: int) -> tuple[int, int]:
    """(sin, cos) in Q14 of an angle in micro-radians (|angle| < 2^32), through the same table
    and a binary angle of 2^-20 turn, rounded: for the geometry words that need more than Q12
    (host/planning/sonar_regions.py). Error <= 1 LSB of Q14 plus the table's interpolation."""
    bam = (int(angle_urad) * URAD_TO_BAM20_Q32 + _BAM_ROUND) >> 32
    return _sin_bam_q14(bam), _sin_bam_q14(bam + _QUARTER_BAM20)


# --- atan2 -----------------------------------------------------------------------------------
_ATAN_STEPS = 256
_ATAN_URAD = tuple(round(1e6 * math.atan(i / _ATAN_STEPS)) for i in range(_ATAN_STEPS + 1))
_RATIO_BITS = 16  # ratio min/max in Q16
_PI_URAD = 3_141_593
_HALF_PI_URAD = 1_570_796


def atan2_urad(y: int, x: int) -> int:
    """atan2(y, x) in micro-radians, in [-pi, pi] (error <= 2 urad + ratio rounding, < 20 urad)."""
    y = int(y)
    x = int(x)
    ax, ay = abs(x), abs(y)
    if ax == 0 and ay == 0:
        return 0
    swap = ay > ax
    num, den = (ax, ay) if swap else (ay, ax)
    ratio = ((num << _RATIO_BITS) + (den >> 1)) // den  # Q16 in [0, 1]
    shift = _RATIO_BITS - 8
    idx = ratio >> shift
    frac = ratio & ((1 << shift) - 1)
    a = _ATAN_URAD[idx]
    b = _ATAN_URAD[idx + 1] if idx < _ATAN_STEPS else a
    ang = a + (((b - a) * frac + (1 << (shift - 1))) >> shift)
    if swap:
        ang = _HALF_PI_URAD - ang
    if x < 0:
        ang = _PI_URAD - ang
    return -ang if y < 0 else ang


def atan2_mrad(y: int, x: int) -> int:
    """atan2(y, x) in milliradians, rounded, in [-3142, 3142] (error <= 1 mrad)."""
    u = atan2_urad(y, x)
    return (u + 500) // 1000 if u >= 0 else -((-u + 500) // 1000)


# --- roots, products, division ---------------------------------------------------------------
def isqrt(n: int) -> int:
    """Exact floor(sqrt(n)) of a non-negative integer.

    The board computes it digit by digit with shifts and adds (:func:`isqrt_digits`); the
    result is the same exact integer, so the host takes ``math.isqrt`` (C, ~30x fewer Python
    steps per call). Its modelled cost is charged through OpCounts, not measured here."""
    n = int(n)
    if n < 0:
        raise ValueError(f"isqrt: negative argument {n}")
    return math.isqrt(n)


def isqrt_digits(n: int) -> int:
    """floor(sqrt(n)) digit by digit (shifts and adds only), as the C port computes it."""
    n = int(n)
    if n < 0:
        raise ValueError(f"isqrt: negative argument {n}")
    bit = 1 << ((n.bit_length() - 1) & ~1) if n else 0
    res = 0
    while bit:
        if n >= res + bit:
            n -= res + bit
            res = (res >> 1) + bit
        else:
            res >>= 1
        bit >>= 2
    return res


def hypot_int(x: int, y: int) -> int:
    """floor(sqrt(x^2 + y^2)) for integers."""
    return isqrt(int(x) * int(x) + int(y) * int(y))


def mul_q12(a: int, b: int) -> int:
    """Product of two Q12 numbers (or a Q12 and a plain integer, giving that unit) rounded."""
    return (int(a) * int(b) + (ONE_Q12 >> 1)) >> Q12_SHIFT


def div_round(num: int, den: int) -> int:
    """num / den rounded to nearest (halves away from zero); ValueError if den == 0."""
    if type(num) is int and type(den) is int and den > 0:  # the usual call
        # floor((2|num| + den) / 2den) is |num|/den rounded with halves up; the sign after
        if num >= 0:
            return (2 * num + den) // (2 * den)
        return -((den - 2 * num) // (2 * den))
    num, den = int(num), int(den)
    if den == 0:
        raise ValueError("div_round: division by zero")
    q, r = divmod(abs(num), abs(den))
    if 2 * r >= abs(den):
        q += 1
    return q if (num >= 0) == (den > 0) else -q


def div_q12(a: int, b: int) -> int:
    """a / b in Q12 for a, b in the same unit (rounded); ValueError if b == 0."""
    return div_round(int(a) << Q12_SHIFT, b)


def q12_from_float(x: float) -> int:
    """Configuration-time conversion of a float constant to Q12 (never in a loop)."""
    return int(round(float(x) * ONE_Q12))


def mrad_from_rad(x: float) -> int:
    """Configuration-time conversion of radians (float) to integer mrad."""
    return int(round(float(x) * 1000.0))


# --- 3x3 rotations (Q12) ---------------------------------------------------------------------
MatQ12 = tuple[tuple[int, int, int], tuple[int, int, int], tuple[int, int, int]]
IDENTITY_Q12: MatQ12 = ((ONE_Q12, 0, 0), (0, ONE_Q12, 0), (0, 0, ONE_Q12))


def rot_x_q12(angle_mrad: int) -> MatQ12:
    """Right-handed rotation about x by angle_mrad, Q12 entries."""
    s, c = sincos_q12(angle_mrad)
    return ((ONE_Q12, 0, 0), (0, c, -s), (0, s, c))


def rot_y_q12(angle_mrad: int) -> MatQ12:
    """Right-handed rotation about y by angle_mrad, Q12 entries."""
    s, c = sincos_q12(angle_mrad)
    return ((c, 0, s), (0, ONE_Q12, 0), (-s, 0, c))


def rot_z_q12(angle_mrad: int) -> MatQ12:
    """Right-handed rotation about z by angle_mrad (counter-clockwise seen from +z), Q12."""
    s, c = sincos_q12(angle_mrad)
    return ((c, -s, 0), (s, c, 0), (0, 0, ONE_Q12))


def _check3(name: str, v: Sequence) -> None:
    if len(v) != 3:
        raise ValueError(f"{name}: expected 3 elements, got {len(v)}")


def matvec_q12(m: Sequence[Sequence[int]], v: Sequence[int]) -> tuple[int, int, int]:
    """M v for a Q12 matrix M and an integer vector v; the result has v's unit, rounded."""
    _check3("matvec_q12 matrix", m)
    _check3("matvec_q12 vector", v)
    out = []
    for row in m:
        _check3("matvec_q12 row", row)
        acc = int(row[0]) * int(v[0]) + int(row[1]) * int(v[1]) + int(row[2]) * int(v[2])
        out.append((acc + (ONE_Q12 >> 1)) >> Q12_SHIFT)
    return out[0], out[1], out[2]


def matmul_q12(a: Sequence[Sequence[int]], b: Sequence[Sequence[int]]) -> MatQ12:
    """A B for two Q12 matrices, Q12 result (rounded)."""
    _check3("matmul_q12 a", a)
    _check3("matmul_q12 b", b)
    cols = [matvec_q12(a, (b[0][j], b[1][j], b[2][j])) for j in range(3)]
    return tuple(tuple(cols[j][i] for j in range(3)) for i in range(3))  # type: ignore[return-value]


def transpose_q12(m: Sequence[Sequence[int]]) -> MatQ12:
    """Transpose (= inverse of a rotation)."""
    _check3("transpose_q12", m)
    return tuple(tuple(int(m[j][i]) for j in range(3)) for i in range(3))  # type: ignore[return-value]


# --- operation counts (ARM920T, host.budget) -------------------------------------------------
def sin_ops() -> OpCounts:
    """One sin_q12 / cos_q12: SMULL scale, quadrant fold, two LUT loads, one interpolation MUL."""
    return OpCounts(alu=10, branches=2, muls32=1, muls=1, luts=2)


def atan2_ops() -> OpCounts:
    """One atan2_mrad: abs/octant logic, one divide, two LUT loads, one MUL, rounding."""
    return OpCounts(alu=14, branches=4, divs=1, luts=2, muls=1)


def isqrt_ops(n: int) -> OpCounts:
    """One isqrt(n): one compare/subtract/shift round per pair of bits of n."""
    rounds = max(1, (int(n).bit_length() + 1) // 2)
    return OpCounts(alu=4 * rounds, branches=rounds)


def mul_q12_ops(k: int = 1) -> OpCounts:
    """k Q12 multiplies with rounding."""
    return OpCounts(muls32=k, alu=2 * k)


def matvec_ops() -> OpCounts:
    """One 3x3 Q12 mat-vec: 9 MUL/MLA (32-bit), 3 rounding shifts."""
    return OpCounts(muls32=9, alu=6)


def rot_ops() -> OpCounts:
    """Building one elementary rotation: a sin and a cos."""
    return sin_ops().scaled(2)
