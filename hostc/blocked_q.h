/* The path-update test of 001 §III.E in fixed point (host/planning/blocked_q.py): does the rest
 * of the present curve enter an infeasible region of eq. (16)? Control points in 1/16 mm and
 * 1/16 ms (12 words), tau in Q15, the regions as bezier.h's geo. */
#ifndef MG_BLOCKED_Q_H
#define MG_BLOCKED_Q_H

#include <stdint.h>

#include "budget.h"

/* the least tau (Q15) with t(tau) >= t_q4 (1/16 ms) by bisection: 0 before the start, 2^15
 * after the end */
int32_t mg_tau_at_time_q15(const int32_t *ctrl, int64_t t_q4);
/* the first of the m - 1 samples after tau0 (m >= 2) inside any region: 1 and its x, y
 * (1/16 mm) in where, or 0 when clear; *ops the test's ARM9 cost */
/* the positions (1/16 mm) of the curve at tau_j = (j << 15) / (n - 1), j = 0..n-1 (n >= 2),
 * by Horner's rule as bezier_q.py horner_q */
void mg_curve_positions_q(const int32_t *ctrl, int32_t n, int64_t *x, int64_t *y);
int mg_first_blocked_q(const int32_t *ctrl, int32_t tau0_q15, int32_t m, const int64_t *geo,
                       int32_t n_reg, int64_t where[2], mg_ops_t *ops);

#endif
