/* The candidates' control points in integers (host/planning/control_points.py), 000 §III.B.1
 * and eqs. (7)-(11) of 001:
 *   P1 = (x_s + u dd_s d0x, y_s + u dd_s d0y, u dd_s / v0)            (8)
 *   P2 = (x_e - u dd_e d3x, y_e - u dd_e d3y, t3 - u dd_e / v3)       (9)
 *   dd_e = |q_s P_i| / N_i (10), dd_s = dd_e / 4 (11), v3 = v0, t3 = |q_s P_i| / v0 (7).
 * The per-plan numbers are rounded once; a candidate costs products and shifts only. */
#include "control_points.h"

#include "div_round.h"
#include "fixedpoint.h"
#include "isqrt.h"

#define MM_PER_Q4_TIME 1000 /* (1/16 mm) / (mm/s) = 1000 (1/16 ms) */

int mg_unit_q14(int64_t dx, int64_t dy, int32_t out[2])
{
    const int64_t n = mg_isqrt64((uint64_t)(dx * dx + dy * dy));
    if (n == 0)
        return 0;
    out[0] = (int32_t)mg_div_round_i64(dx * (1 << MG_DIR_BITS), n);
    out[1] = (int32_t)mg_div_round_i64(dy * (1 << MG_DIR_BITS), n);
    return 1;
}

void mg_heading_q14(int32_t heading_mrad, int32_t out[2])
{
    out[0] = mg_cos_q12(heading_mrad) * 4;
    out[1] = mg_sin_q12(heading_mrad) * 4;
}

void mg_start_direction_q(const int64_t vel_q4[2], int has_heading, int32_t heading_mrad,
                          const int32_t fallback_q14[2], int64_t moving_q4, int32_t out[2])
{
    if (vel_q4[0] * vel_q4[0] + vel_q4[1] * vel_q4[1] >= moving_q4 * moving_q4
        && mg_unit_q14(vel_q4[0], vel_q4[1], out))
        return;
    if (has_heading) {
        mg_heading_q14(heading_mrad, out);
        return;
    }
    out[0] = fallback_q14[0];
    out[1] = fallback_q14[1];
}

int mg_plan_numbers(int64_t dist_q4, int32_t v0_mm_s, int32_t t_s_ms, mg_plan_numbers_t *out)
{
    if (dist_q4 < 0 || v0_mm_s <= 0 || t_s_ms <= 0)
        return -1;
    out->t3 = mg_div_round_i64(dist_q4 * MM_PER_Q4_TIME, v0_mm_s); /* eq. (7) */
    out->n_i = out->t3 / ((int64_t)t_s_ms * 16);
    if (out->n_i < 1)
        out->n_i = 1;
    out->dd_e = mg_div_round_i64(dist_q4, out->n_i);      /* eq. (10) */
    out->dd_s = mg_div_round_i64(dist_q4, 4 * out->n_i);  /* eq. (11), rounded once */
    out->dt_e = mg_div_round_i64(dist_q4 * MM_PER_Q4_TIME, out->n_i * v0_mm_s);
    out->dt_s = mg_div_round_i64(dist_q4 * MM_PER_Q4_TIME, 4 * out->n_i * v0_mm_s);
    return 0;
}

/* u dd d (Q14) to 1/16 mm, halves away from zero */
static int64_t step(int64_t u, int64_t d, int32_t dir)
{
    const int64_t p = u * d * dir, half = (int64_t)1 << (MG_DIR_BITS - 1);
    return p >= 0 ? (p + half) >> MG_DIR_BITS : -((half - p) >> MG_DIR_BITS);
}

void mg_control_point_row(const int64_t p0_q4[2], const int32_t d0_q14[2],
                          const int64_t end_q4[2], const int32_t d3_q14[2],
                          const mg_plan_numbers_t *num, int64_t u, int32_t *row)
{
    row[0] = (int32_t)p0_q4[0];
    row[1] = (int32_t)p0_q4[1];
    row[2] = 0;
    row[3] = (int32_t)(p0_q4[0] + step(u, num->dd_s, d0_q14[0]));
    row[4] = (int32_t)(p0_q4[1] + step(u, num->dd_s, d0_q14[1]));
    row[5] = (int32_t)(u * num->dt_s);
    row[6] = (int32_t)(end_q4[0] - step(u, num->dd_e, d3_q14[0]));
    row[7] = (int32_t)(end_q4[1] - step(u, num->dd_e, d3_q14[1]));
    row[8] = (int32_t)(num->t3 - u * num->dt_e); /* v3 = v0 */
    row[9] = (int32_t)end_q4[0];
    row[10] = (int32_t)end_q4[1];
    row[11] = (int32_t)num->t3;
}

int32_t mg_control_points_q(const int64_t p0_q4[2], const int32_t d0_q14[2],
                            const int64_t *ends_q4, const int32_t *d3_q14, int32_t n_end,
                            const mg_plan_numbers_t *num, int32_t *ctrl, int32_t cap)
{
    if (n_end < 0 || num->n_i < 1 || (int64_t)n_end * num->n_i > cap)
        return -1;
    int32_t *row = ctrl;
    for (int32_t k = 0; k < n_end; k++)
        for (int64_t u = 1; u <= num->n_i; u++, row += 12)
            mg_control_point_row(p0_q4, d0_q14, ends_q4 + 2 * k, d3_q14 + 2 * k, num, u, row);
    return (int32_t)(n_end * num->n_i);
}
