/* The path-update test of 001 §III.E in fixed point (host/planning/blocked_q.py): the present
 * tau where t(tau) (000's eq. (5), the time row) reaches the present time, by bisection over
 * the Q15 grid; then the rest [tau_now, 1] at m - 1 samples tau_j = tau_now + (2^15 - tau_now)
 * j / (m - 1), each tested against the regions as the planner does (bezier.c). */
#include "blocked_q.h"

#include "bezier.h"
#include "candidates.h"

#define TAU_BITS 15
#define TAU_ONE (1 << TAU_BITS)

/* one halving: t(tau) by Horner's rule, compare, move a bound (blocked_q.py HALVING_OPS) */
static const mg_ops_t HALVING = {0, 0, 10, 2, 0, 9, 0, 0, 0, 0, 0};

/* eq. (6) of 000's coefficients of coordinate c and the position at tau (Horner's rule) */
static void coefficients(const int32_t *ctrl, int c, int64_t k[4])
{
    const int64_t p0 = ctrl[c], p1 = ctrl[3 + c], p2 = ctrl[6 + c], p3 = ctrl[9 + c];
    k[0] = p0;
    k[1] = 3 * (p1 - p0);
    k[2] = 3 * (p0 - 2 * p1 + p2);
    k[3] = -p0 + 3 * p1 - 3 * p2 + p3;
}

static int64_t position(const int64_t k[4], int64_t tau)
{
    return k[0]
           + ((tau * (k[1] + ((tau * (k[2] + ((tau * k[3]) >> TAU_BITS))) >> TAU_BITS)))
              >> TAU_BITS);
}

int32_t mg_tau_at_time_q15(const int32_t *ctrl, int64_t t_q4)
{
    int64_t k[4];
    coefficients(ctrl, 2, k);
    int32_t lo = 0, hi = TAU_ONE;
    while (lo < hi) {
        const int32_t mid = (lo + hi) >> 1;
        if (position(k, mid) < t_q4)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

void mg_curve_positions_q(const int32_t *ctrl, int32_t n, int64_t *x, int64_t *y)
{
    int64_t kx[4], ky[4];
    coefficients(ctrl, 0, kx);
    coefficients(ctrl, 1, ky);
    for (int32_t j = 0; j < n; j++) {
        const int64_t tau = ((int64_t)j << TAU_BITS) / (n - 1);
        x[j] = position(kx, tau);
        y[j] = position(ky, tau);
    }
}

int mg_first_blocked_q(const int32_t *ctrl, int32_t tau0_q15, int32_t m, const int64_t *geo,
                       int32_t n_reg, int64_t where[2], mg_ops_t *ops)
{
    const mg_ops_t per = mg_ops_add(mg_position_ops(),
                                    mg_ops_scaled(mg_region_sample_ops(), n_reg));
    *ops = mg_ops_add(mg_ops_scaled(per, m - 1), mg_ops_scaled(HALVING, TAU_BITS + 1));
    int64_t kx[4], ky[4];
    coefficients(ctrl, 0, kx);
    coefficients(ctrl, 1, ky);
    for (int32_t j = 1; j < m; j++) {
        const int64_t tau = tau0_q15 + (int64_t)(TAU_ONE - tau0_q15) * j / (m - 1);
        const int64_t x = position(kx, tau), y = position(ky, tau);
        if (mg_bezier_in_regions(geo, n_reg, x, y)) {
            where[0] = x;
            where[1] = y;
            return 1;
        }
    }
    return 0;
}
