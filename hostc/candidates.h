/* Candidate sets of Bezier paths (host/planning/candidates.py): the sampling of a set within
 * an ARM9 budget and the cost of a batch with early exit (with bezier_q.py's counts of a
 * curve). */
#ifndef MG_CANDIDATES_H
#define MG_CANDIDATES_H

#include <stdint.h>

#include "budget.h"

/* the ARM920T cost of one curve of bezier.c at n_samples (bezier_q.py sample_ops; 64-bit
 * quotients per sample: 3 for 001, 6 for 000) and of the integrals and cost of a curve that
 * passes (PASS_OPS) */
mg_ops_t mg_sample_ops(int32_t n_samples, int positions, int grasp_circle, int32_t regions,
                       int32_t divs_per_sample);
mg_ops_t mg_pass_ops(void);
/* bezier_q.py POSITION_OPS (a sample's x, y) and REGION_OPS_PER_SAMPLE (one region's test) */
mg_ops_t mg_position_ops(void);
mg_ops_t mg_region_sample_ops(void);
/* samples per curve and the stride over candidates so that the set fits budget_us (the worst
 * case, no early exit; candidates.py choose_sampling) */
void mg_choose_sampling(int64_t n_candidates, int64_t cycles_per_sample, int64_t budget_us,
                        int32_t n_min, int32_t n_max, int32_t *n, int32_t *stride);
/* the ARM9 cost of one curve of a batch (candidates.py batch_ops): rejected at sample first
 * (n: none) it costs min(first + 1, n) samples and the set-up, passed also PASS_OPS */
mg_ops_t mg_curve_ops(int32_t first, int32_t n, int positions, int grasp_circle,
                      int32_t regions, int32_t divs_per_sample);

#endif
