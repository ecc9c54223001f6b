/* The candidate evaluation of 001's planning among obstacles (host/planning/bezier001.py
 * plan_001): the coarse pass over the candidate set and the fine check of the cheapest ones.
 *
 * Coarse: each curve (end point k_e, spacing u) checked at n samples against the coarse limits
 * (v, a_t = v^2 kappa of eq. (14)), the grasp circle and the grown infeasible regions of
 * eq. (16), its cost of eq. (17) (Q16) when it passes; the pass stops taking curves once the
 * modelled cycles of the curves taken so far exceed cut_cycles (the anytime cut: a curve
 * rejected at sample j costs (j + 1) per_sample_cycles + setup_cycles), and the curve that
 * crosses it and every later one get the reason "budget".
 *
 * Fine: candidates in the caller's order (eq. (18)'s pool by cost) re-checked at n samples
 * against the true limits and regions until one passes, each only while the modelled time
 * spent plus the worst case of one more (worst_us) stays within budget_us. */
#include "bezier.h"
#include "kernels.h"

/* One slice of the coarse pass: state[0] the next candidate, state[1] the modelled cycles of
 * the pass so far (the anytime cut's count); candidates are started while that count is below
 * slice_end_cycles. Returns the curves taken when the pass has ended (the cut or the last
 * candidate), -1 when it goes on in a later slice. */
int32_t mg_bezier001_coarse_slice(const int32_t *ctrl, int32_t n_cand, int32_t n,
                                  const int32_t *lim, const int64_t *geo, int32_t n_reg,
                                  int32_t per_sample_cycles, int32_t setup_cycles,
                                  int32_t cut_cycles, int32_t k1_q16, int32_t k2_q16,
                                  int32_t slice_end_cycles, int32_t *state, int32_t *reason,
                                  int32_t *first, int64_t *cost)
{
    int32_t spent = state[1], i = state[0];
    int cut = 0;
    for (; i < n_cand && spent < slice_end_cycles; i++) {
        int64_t len = 0, kint = 0;
        reason[i] = mg_bezier_curve(ctrl + 12 * i, n, lim, geo, n_reg, first + i, &len,
                                    &kint);
        const int32_t used = first[i] + 1 < n ? first[i] + 1 : n;
        spent += used * per_sample_cycles + setup_cycles;
        cost[i] = INT64_MAX;
        if (spent > cut_cycles) {
            cut = 1;
            break;
        }
        if (reason[i] == MG_OK)
            cost[i] = mg_bezier_cost(k1_q16, k2_q16, len, kint);
    }
    state[0] = i;
    state[1] = spent;
    if (!cut && i < n_cand)
        return -1;
    const int32_t taken = i;
    for (; i < n_cand; i++) {
        reason[i] = MG_BUDGET;
        cost[i] = INT64_MAX;
        if (i > taken)
            first[i] = n;
    }
    state[0] = n_cand;
    return taken;
}

int32_t mg_bezier001_coarse(const int32_t *ctrl, int32_t n_cand, int32_t n,
                            const int32_t *lim, const int64_t *geo, int32_t n_reg,
                            int32_t per_sample_cycles, int32_t setup_cycles, int32_t cut_cycles,
                            int32_t k1_q16, int32_t k2_q16, int32_t *reason, int32_t *first,
                            int64_t *cost)
{
    int32_t state[2] = {0, 0};
    return mg_bezier001_coarse_slice(ctrl, n_cand, n, lim, geo, n_reg, per_sample_cycles,
                                     setup_cycles, cut_cycles, k1_q16, k2_q16, INT32_MAX,
                                     state, reason, first, cost);
}

/* One slice of the fine check: state[0] the next candidate of the pool, state[1] the modelled
 * cycles spent so far; candidates are started while that count is below slice_end_cycles.
 * Returns the index of the first that passes, -1 when none does (the pool or the budget
 * spent: *tried says how many were checked in all), -2 when it goes on in a later slice. */
int32_t mg_bezier001_fine_slice(const int32_t *ctrl, int32_t n_pool, int32_t n,
                                const int32_t *lim, const int64_t *geo, int32_t n_reg,
                                int32_t per_sample_cycles, int32_t setup_cycles,
                                int32_t worst_us, int32_t budget_us, int32_t slice_end_cycles,
                                int32_t *state, int32_t *reason, int32_t *tried)
{
    int32_t cycles = state[1];
    for (int32_t i = state[0]; i < n_pool; i++) {
        if ((cycles + 399) / 400 + worst_us > budget_us) {  /* µs at 400 MHz, rounded up */
            *tried = i;
            state[0] = n_pool;
            return -1;
        }
        if (cycles >= slice_end_cycles) {
            state[0] = i;
            state[1] = cycles;
            return -2;
        }
        int64_t len = 0, kint = 0;
        int32_t first = 0;
        reason[i] = mg_bezier_curve(ctrl + 12 * i, n, lim, geo, n_reg, &first, &len, &kint);
        cycles += (first + 1 < n ? first + 1 : n) * per_sample_cycles + setup_cycles;
        if (reason[i] == MG_OK) {
            *tried = i + 1;
            state[0] = n_pool;
            state[1] = cycles;
            return i;
        }
    }
    *tried = n_pool;
    state[0] = n_pool;
    state[1] = cycles;
    return -1;
}

int32_t mg_bezier001_fine(const int32_t *ctrl, int32_t n_pool, int32_t n, const int32_t *lim,
                          const int64_t *geo, int32_t n_reg, int32_t per_sample_cycles,
                          int32_t setup_cycles, int32_t worst_us, int32_t budget_us,
                          int32_t *reason, int32_t *tried)
{
    int32_t state[2] = {0, 0};
    return mg_bezier001_fine_slice(ctrl, n_pool, n, lim, geo, n_reg, per_sample_cycles,
                                   setup_cycles, worst_us, budget_us, INT32_MAX, state,
                                   reason, tried);
}
