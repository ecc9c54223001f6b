/* Integer roots, rounded products and divisions, and 3x3 Q12 rotations (host/fixedpoint.py);
 * the sine, cosine and atan2 tables are in trig.c. */
#include "fixedpoint.h"

#include "div_round.h"
#include "isqrt.h"

int64_t mg_isqrt(int64_t n)
{
    return n < 0 ? -1 : mg_isqrt64((uint64_t)n);
}

int64_t mg_hypot_int(int64_t x, int64_t y)
{
    return mg_isqrt(x * x + y * y);
}

int64_t mg_mul_q12(int64_t a, int64_t b)
{
    return mg_mul_q12_i64(a, b);
}

int64_t mg_div_round64(int64_t num, int64_t den)
{
    return mg_div_round_i64(num, den);
}

int64_t mg_div_q12(int64_t a, int64_t b)
{
    return mg_div_round64(a * MG_ONE_Q12, b);
}

int64_t mg_floor_div(int64_t a, int64_t b)
{
    const int64_t q = a / b;
    return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

int64_t mg_floor_mod(int64_t a, int64_t b)
{
    return a - mg_floor_div(a, b) * b;
}

int32_t mg_urad_to_mrad(int64_t urad)
{
    return (int32_t)(urad >= 0 ? (urad + 500) / 1000 : -((-urad + 500) / 1000));
}

/* elementary right-handed rotations, Q12 entries */
static void fill(mg_mat_q12 out, int32_t a, int32_t b, int32_t c, int32_t d, int32_t e,
                 int32_t f, int32_t g, int32_t h, int32_t i)
{
    out[0][0] = a, out[0][1] = b, out[0][2] = c;
    out[1][0] = d, out[1][1] = e, out[1][2] = f;
    out[2][0] = g, out[2][1] = h, out[2][2] = i;
}

void mg_rot_x_q12(int32_t angle_mrad, mg_mat_q12 out)
{
    const int32_t s = mg_sin_q12(angle_mrad), c = mg_cos_q12(angle_mrad);
    fill(out, MG_ONE_Q12, 0, 0, 0, c, -s, 0, s, c);
}

void mg_rot_y_q12(int32_t angle_mrad, mg_mat_q12 out)
{
    const int32_t s = mg_sin_q12(angle_mrad), c = mg_cos_q12(angle_mrad);
    fill(out, c, 0, s, 0, MG_ONE_Q12, 0, -s, 0, c);
}

void mg_rot_z_q12(int32_t angle_mrad, mg_mat_q12 out)
{
    const int32_t s = mg_sin_q12(angle_mrad), c = mg_cos_q12(angle_mrad);
    fill(out, c, -s, 0, s, c, 0, 0, 0, MG_ONE_Q12);
}

void mg_matvec_q12(const mg_mat_q12 m, const int32_t v[3], int32_t out[3])
{
    int32_t r[3];
    for (int i = 0; i < 3; i++) {
        const int64_t acc = (int64_t)m[i][0] * v[0] + (int64_t)m[i][1] * v[1]
                            + (int64_t)m[i][2] * v[2];
        r[i] = (int32_t)((acc + (MG_ONE_Q12 >> 1)) >> MG_Q12_SHIFT);
    }
    out[0] = r[0], out[1] = r[1], out[2] = r[2];
}

void mg_matmul_q12(const mg_mat_q12 a, const mg_mat_q12 b, mg_mat_q12 out)
{
    mg_mat_q12 r;
    for (int j = 0; j < 3; j++) {
        const int32_t col[3] = {b[0][j], b[1][j], b[2][j]};
        int32_t p[3];
        mg_matvec_q12(a, col, p);
        r[0][j] = p[0], r[1][j] = p[1], r[2][j] = p[2];
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[i][j] = r[i][j];
}

void mg_transpose_q12(const mg_mat_q12 m, mg_mat_q12 out)
{
    mg_mat_q12 r;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r[i][j] = m[j][i];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[i][j] = r[i][j];
}

/* --- operation counts (host/fixedpoint.py) --- */
static mg_ops_t ops(int64_t alu, int64_t branches, int64_t muls, int64_t muls32, int64_t divs,
                    int64_t luts)
{
    mg_ops_t o = {0, 0, alu, branches, muls, muls32, divs, luts, 0, 0, 0};
    return o;
}

mg_ops_t mg_sin_ops(void)
{
    /* SMULL scale, quadrant fold, two table loads, one interpolation MUL */
    return ops(10, 2, 1, 1, 0, 2);
}

mg_ops_t mg_atan2_ops(void)
{
    /* abs/octant logic, one divide, two table loads, one MUL, rounding */
    return ops(14, 4, 1, 0, 1, 2);
}

mg_ops_t mg_isqrt_ops(int64_t n)
{
    /* one compare/subtract/shift round per pair of bits of n */
    int bits = 0;
    for (uint64_t u = (uint64_t)(n < 0 ? -n : n); u; u >>= 1)
        bits++;
    const int64_t rounds = (bits + 1) / 2 > 1 ? (bits + 1) / 2 : 1;
    return ops(4 * rounds, rounds, 0, 0, 0, 0);
}

mg_ops_t mg_mul_q12_ops(int32_t k)
{
    return ops(2 * (int64_t)k, 0, 0, k, 0, 0);
}

mg_ops_t mg_matvec_ops(void)
{
    return ops(6, 0, 0, 9, 0, 0);
}

mg_ops_t mg_rot_ops(void)
{
    return mg_ops_scaled(mg_sin_ops(), 2);
}

int64_t mg_div_even64(int64_t num, int64_t den)
{
    int64_t q = num / den, r = num % den;
    if (r < 0)
        q--, r += den; /* floor */
    if (2 * r > den || (2 * r == den && (q & 1)))
        q++;
    return q;
}
