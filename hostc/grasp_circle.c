/* The end points of 001's grasp circle (host/planning/grasp_circle.py end_points_q), eq. (6):
 * x_e = x_i + l_e cos phi_k, y_e = y_i + l_e sin phi_k, phi_k = 2 pi k / n_e, k = 1..n_e. */
#include "grasp_circle.h"

#include "div_round.h"
#include "fixedpoint.h"
#include "trig.h"

int mg_end_points_q(const int64_t object_q4[2], int64_t l_e_q4, int32_t n_e, int64_t *ends_q4,
                    int32_t *dirs_q14)
{
    if (n_e < 1 || l_e_q4 <= 0)
        return -1;
    for (int32_t i = 0; i < n_e; i++) {
        int32_t s, c; /* phi_k: (i + 1) / n_e of a turn, exact at the quarter turns */
        mg_sincos_turn_q12(i + 1, n_e, &s, &c);
        ends_q4[2 * i] = object_q4[0] + mg_div_round_i64(l_e_q4 * c, 4096);
        ends_q4[2 * i + 1] = object_q4[1] + mg_div_round_i64(l_e_q4 * s, 4096);
        dirs_q14[2 * i] = -c * 4;
        dirs_q14[2 * i + 1] = -s * 4;
    }
    return 0;
}

#define HALF_PI_URAD 1570796
#define PI_URAD 3141593
#define TWO_PI_URAD 6283185

int mg_grasp_radius_um(int64_t l1_um, int64_t l2_um, int64_t l3_um, int64_t h_r_um,
                       int64_t h_e_um, int32_t steps, int64_t out_um[2])
{
    const int64_t d_um = h_e_um - h_r_um;
    int64_t hi = -1, lo = -1;
    if (steps < 1 || l1_um <= 0)
        return -1;
    for (int32_t i = 0; i <= steps; i++) {
        const int64_t t2 = mg_div_round_i64((int64_t)(2 * i - steps) * HALF_PI_URAD, steps);
        for (int32_t j = 0; j <= steps; j++) {
            const int64_t t3 = mg_div_round_i64((int64_t)(2 * j - steps) * HALF_PI_URAD, steps);
            int32_t s3, c3, s23, c23;
            mg_sincos_urad_q14(t3, &s3, &c3);
            mg_sincos_urad_q14(t2 + t3, &s23, &c23);
            /* l1 sin(theta1 + theta2 + theta3), um Q14 */
            const int64_t num = d_um * 16384 - l3_um * s3 - l2_um * s23;
            if ((num < 0 ? -num : num) > l1_um * 16384)
                continue;
            const int64_t rest = mg_div_round_i64(num, l1_um); /* Q14 */
            const int64_t base = mg_atan2_urad(rest, mg_isqrt(((int64_t)1 << 28) - rest * rest));
            const int64_t roots[2] = {base, PI_URAD - base};
            for (int32_t k = 0; k < 2; k++) {
                int64_t t1 = roots[k] - t2 - t3;
                t1 = t1 < 0 ? t1 + TWO_PI_URAD : t1;
                t1 = t1 > TWO_PI_URAD ? t1 - TWO_PI_URAD : t1;
                if (t1 > PI_URAD)
                    continue;
                int32_t s123, c123;
                mg_sincos_urad_q14(roots[k], &s123, &c123);
                const int64_t reach =
                    mg_floor_div(l3_um * c3 + l2_um * c23 + l1_um * c123, 16384);
                if (reach >= 0) {
                    hi = reach > hi ? reach : hi;
                    lo = lo < 0 || reach < lo ? reach : lo;
                }
            }
        }
    }
    if (hi < 0)
        return -1;
    out_um[0] = hi;
    out_um[1] = lo;
    return 0;
}

int mg_grasp_radius001_um(int32_t h_e_mm, int64_t out_um[2])
{
    return mg_grasp_radius_um(160000, 160000, 200000, 108000, (int64_t)h_e_mm * 1000,
                              MG_GRASP_GRID_STEPS, out_um);
}
