/* The candidate set of 000's approach planning (host/planning/bezier000.py plan_000 after its
 * set-up): every candidate curve u checked at n samples against v <= Vmax, |a_t| <= Amax and
 * R >= R_min (000 §III.B.1), the cost of eq. (9) k1 length + k2 integral |kappa| dtau of each
 * feasible one (Q16), and the first minimum (the smallest u). */
#include "bezier.h"
#include "kernels.h"

int32_t mg_bezier000(const int32_t *ctrl, int32_t n_cand, int32_t n, const int32_t *lim,
                     int32_t k1_q16, int32_t k2_q16, int32_t *reason, int32_t *first,
                     int64_t *cost)
{
    int32_t best = -1;
    for (int32_t i = 0; i < n_cand; i++) {
        int64_t len = 0, kint = 0;
        reason[i] = mg_bezier_curve(ctrl + 12 * i, n, lim, 0, 0, first + i, &len, &kint);
        cost[i] = INT64_MAX;
        if (reason[i] == MG_OK) {
            cost[i] = mg_bezier_cost(k1_q16, k2_q16, len, kint);
            if (best < 0 || cost[i] < cost[best])
                best = i;
        }
    }
    return best;
}
