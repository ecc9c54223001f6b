/* One candidate curve of the Bezier planners checked in fixed point as
 * host/planning/bezier_q.py evaluate_q does (formats and bounds there): the power-form
 * coefficients of eq. (6) of 000, a range check and t_tau > 0 on [0, 1] exactly before the
 * first sample, then per sample tau_j in the Python's order (grasp circle and infeasible
 * regions for 001, time increasing, speed, acceleration, and the turning radius for 000),
 * stopping at the first violation. The derivatives of eq. (7) by Horner's rule with arithmetic
 * shifts; quotients of signed numbers truncate (C's /), as the Python's _tdiv. */
#include "bezier.h"
#include "isqrt.h"

#define TAU_BITS 15
#define TRIG_BITS 14
#define COORD_LIMIT (1 << 21)
#define KAPPA_SAT 2147483647LL
#define KAPPA_SCALE 16384000LL /* 16000 * 2^16 >> 6 */
#define POS_PER_M 16000

static int64_t iabs64(int64_t a)
{
    return a < 0 ? -a : a;
}

/* t_tau = c1 + 2 c2 tau + 3 c3 tau^2 > 0 on all of [0, 1] (bezier_q._min_t_positive) */
static int t_positive(int64_t c1, int64_t c2, int64_t c3)
{
    if (!(c1 > 0) || !(c1 + 2 * c2 + 3 * c3 > 0))
        return 0;
    if (c3 > 0 && -c2 > 0 && -c2 < 3 * c3)
        return 3 * c3 * c1 > c2 * c2;
    return 1;
}

static int in_region(const int64_t *r, int64_t x, int64_t y)
{
    const int64_t px = x - r[0], py = y - r[1];
    const int64_t along = px * r[2] + py * r[3];
    if (!(along > 0))
        return 0;
    const int64_t across = iabs64(py * r[2] - px * r[3]);
    if (!((across << TRIG_BITS) <= along * r[4]))
        return 0;
    const int64_t rx = x - r[5], ry = y - r[6];
    const int64_t d2 = rx * rx + ry * ry;
    if (!(d2 >= r[7]) || !(d2 <= r[8]))
        return 0;
    if (r[9] != 0) {
        /* |atan2(a, b)| <= bound  <=>  b >= |(rx, ry)| cos(bound): squared, by the sign of
         * cos(bound) (r[10]), without a root or an arctangent */
        const int64_t b = (rx * r[2] + ry * r[3]) >> TRIG_BITS;
        const int64_t bb = b * b, lim = (d2 * r[11]) >> 16;
        if (r[10] != 0 ? !(b >= 0 && bb >= lim) : !(b >= 0 || bb <= lim))
            return 0;
    }
    return 1;
}

int mg_bezier_in_regions(const int64_t *geo, int32_t n_reg, int64_t x, int64_t y)
{
    for (int32_t r = 0; r < n_reg; r++)
        if (in_region(geo + MG_GEO_HEAD + MG_REGION_WORDS * r, x, y))
            return 1;
    return 0;
}

int32_t mg_bezier_curve(const int32_t *ctrl, int32_t n, const int32_t *lim, const int64_t *geo,
                        int32_t n_reg, int32_t *first, int64_t *len_q4, int64_t *kint_q16)
{
    /* coefficients of eq. (6) per coordinate c (x, y, t): k0 = P0, k1 = 3 (P1 - P0),
     * k2 = 3 (P0 - 2 P1 + P2), k3 = -P0 + 3 P1 - 3 P2 + P3 */
    int64_t k[3][4];
    int range = 0;
    for (int c = 0; c < 3; c++) {
        const int64_t p0 = ctrl[c], p1 = ctrl[3 + c], p2 = ctrl[6 + c], p3 = ctrl[9 + c];
        range |= iabs64(p0) >= COORD_LIMIT || iabs64(p1) >= COORD_LIMIT
            || iabs64(p2) >= COORD_LIMIT || iabs64(p3) >= COORD_LIMIT;
        k[c][0] = p0;
        k[c][1] = 3 * (p1 - p0);
        k[c][2] = 3 * (p0 - 2 * p1 + p2);
        k[c][3] = -p0 + 3 * p1 - 3 * p2 + p3;
    }
    if (range) {
        *first = 0;
        return MG_RANGE;
    }
    const int64_t v_max = lim[0], a_max = lim[1], kappa_max = lim[2];
    const int normal = lim[3] != 0;
    int64_t s_sum = 0, k_sum = 0, s_end = 0, k_end = 0;
    for (int32_t j = 0; j < n; j++) {
        const int64_t tau = (int32_t)(((uint32_t)j << TAU_BITS) / (uint32_t)(n - 1));
        int32_t why = MG_OK;
        if (geo != 0) {
            const int64_t x = k[0][0] + ((tau * (k[0][1] + ((tau * (k[0][2]
                + ((tau * k[0][3]) >> TAU_BITS))) >> TAU_BITS))) >> TAU_BITS);
            const int64_t y = k[1][0] + ((tau * (k[1][1] + ((tau * (k[1][2]
                + ((tau * k[1][3]) >> TAU_BITS))) >> TAU_BITS))) >> TAU_BITS);
            const int64_t dx = x - geo[0], dy = y - geo[1];
            if (dx * dx + dy * dy < geo[2]) {
                why = MG_CIRCLE;
            } else if (j > 0) {  /* the start is where the robot already is */
                for (int32_t r = 0; r < n_reg; r++)
                    if (in_region(geo + MG_GEO_HEAD + MG_REGION_WORDS * r, x, y)) {
                        why = MG_OBSTACLE;
                        break;
                    }
            }
        }
        if (why == MG_OK && j == 0 && !t_positive(k[2][1], k[2][2], k[2][3]))
            why = MG_TIME;
        int64_t s = 0, kappa = 0;
        if (why == MG_OK) {
            int64_t d1[3], d2[3];
            for (int c = 0; c < 3; c++) {
                d1[c] = k[c][1] + ((tau * (2 * k[c][2] + ((tau * (3 * k[c][3])) >> TAU_BITS)))
                                   >> TAU_BITS);
                d2[c] = 2 * k[c][2] + ((tau * (6 * k[c][3])) >> TAU_BITS);
            }
            const int64_t xt = d1[0], yt = d1[1], tt = d1[2];
            s = mg_isqrt64((uint64_t)(xt * xt + yt * yt));
            if (!(tt > 0) || !(s > 0)) {
                why = MG_TIME;
            } else if ((s << 16) > v_max * tt) {
                why = MG_SPEED;
            } else {
                const int64_t cross = iabs64(xt * d2[1] - d2[0] * yt);
                const int64_t q = (cross << 6) / s;
                kappa = q * KAPPA_SCALE / (s * s);
                if (kappa > KAPPA_SAT)
                    kappa = KAPPA_SAT;
                const int64_t v = (s << 16) / tt;
                int64_t acc;
                if (normal) {
                    acc = (((v * v) >> 16) * kappa) >> 16;
                } else {
                    const int64_t sdot = (xt * d2[0] + yt * d2[1]) / s;
                    const int64_t m = sdot * 65536 - v * d2[2];
                    acc = iabs64(m * 250 / tt * 64 / tt);
                }
                if (acc > a_max)
                    why = MG_ACCEL;
                else if (!normal && kappa_max >= 0 && kappa > kappa_max)
                    why = MG_RADIUS;
            }
        }
        if (why != MG_OK) {
            *first = j;
            return why;
        }
        s_sum += s;
        k_sum += kappa;
        if (j == 0 || j == n - 1) {
            s_end += s;
            k_end += kappa;
        }
    }
    *first = n;
    *len_q4 = (2 * s_sum - s_end) / (2 * (n - 1));
    *kint_q16 = (2 * k_sum - k_end) / (2 * (n - 1));
    return MG_OK;
}

int64_t mg_bezier_cost(int32_t k1_q16, int32_t k2_q16, int64_t len_q4, int64_t kint_q16)
{
    return (int64_t)k1_q16 * len_q4 / POS_PER_M + (((int64_t)k2_q16 * kint_q16) >> 16);
}
