/* Candidate sets of Bezier paths (host/planning/candidates.py): sampling and batch cost. */
#include "candidates.h"

#include "fixedpoint.h"

/* bezier_q.py's counts of the C loop of bezier.c: DIV64_OPS a 64-bit quotient (libgcc's
 * shift-subtract loop), ISQRT64_OPS the root, SAMPLE_BASE_OPS, POSITION_OPS, CIRCLE_OPS,
 * REGION_OPS_PER_SAMPLE, CURVE_SETUP_OPS (calibrated: docs/budget.md) */
static const mg_ops_t DIV64 = {0, 0, 270, 20, 0, 0, 0, 0, 0, 0, 0};
static const mg_ops_t ISQRT64 = {0, 0, 432, 54, 0, 0, 0, 0, 0, 0, 0};
static const mg_ops_t SAMPLE_BASE = {0, 0, 120, 4, 0, 36, 1, 0, 0, 0, 0};
static const mg_ops_t POSITION = {0, 0, 20, 0, 0, 18, 0, 0, 0, 0, 0};
static const mg_ops_t CIRCLE = {0, 0, 8, 1, 0, 6, 0, 0, 0, 0, 0};
static const mg_ops_t REGION_PER_SAMPLE = {0, 0, 16, 2, 0, 9, 0, 0, 0, 0, 0};
static const mg_ops_t CURVE_SETUP = {0, 0, 250, 10, 0, 30, 0, 0, 0, 0, 0};

mg_ops_t mg_sample_ops(int32_t n_samples, int positions, int grasp_circle, int32_t regions,
                       int32_t divs_per_sample)
{
    mg_ops_t per = mg_ops_add(mg_ops_add(SAMPLE_BASE, ISQRT64),
                              mg_ops_scaled(DIV64, divs_per_sample));
    if (positions || grasp_circle || regions)
        per = mg_ops_add(per, POSITION);
    if (grasp_circle)
        per = mg_ops_add(per, CIRCLE);
    per = mg_ops_add(per, mg_ops_scaled(REGION_PER_SAMPLE, regions));
    return mg_ops_add(mg_ops_scaled(per, n_samples), CURVE_SETUP);
}

mg_ops_t mg_position_ops(void)
{
    return POSITION;
}

mg_ops_t mg_region_sample_ops(void)
{
    return REGION_PER_SAMPLE;
}

mg_ops_t mg_pass_ops(void)
{
    const mg_ops_t extra = {0, 0, 100, 0, 0, 0, 0, 0, 0, 0, 0};
    return mg_ops_add(mg_ops_scaled(DIV64, 3), extra);
}

void mg_choose_sampling(int64_t n_candidates, int64_t cycles_per_sample, int64_t budget_us,
                        int32_t n_min, int32_t n_max, int32_t *n, int32_t *stride)
{
    /* 400 cycles per us; Python's floor division, for a budget already spent too */
    int64_t budget_samples = mg_floor_div(budget_us * 400,
                                          cycles_per_sample > 1 ? cycles_per_sample : 1);
    if (budget_samples < 1)
        budget_samples = 1;
    int64_t each = mg_floor_div(budget_samples, n_candidates > 1 ? n_candidates : 1);
    if (each < n_min)
        each = n_min;
    if (each > n_max)
        each = n_max;
    int64_t s = 1;
    while ((n_candidates + s - 1) / s * each > budget_samples && s < n_candidates)
        s++;
    *n = (int32_t)each;
    *stride = (int32_t)s;
}

mg_ops_t mg_curve_ops(int32_t first, int32_t n, int positions, int grasp_circle,
                      int32_t regions, int32_t divs_per_sample)
{
    const mg_ops_t setup = mg_sample_ops(0, positions, grasp_circle, regions, divs_per_sample);
    const mg_ops_t one = mg_sample_ops(1, positions, grasp_circle, regions, divs_per_sample);
    mg_ops_t per = one;
    per.pixels_read -= setup.pixels_read, per.pixels_written -= setup.pixels_written;
    per.alu -= setup.alu, per.branches -= setup.branches, per.muls -= setup.muls;
    per.muls32 -= setup.muls32, per.divs -= setup.divs, per.luts -= setup.luts;
    per.float_ops -= setup.float_ops, per.float_divs -= setup.float_divs;
    per.bytes_streamed -= setup.bytes_streamed;
    mg_ops_t ops = mg_ops_add(mg_ops_scaled(per, first + 1 < n ? first + 1 : n), setup);
    if (first >= n)
        ops = mg_ops_add(ops, mg_pass_ops());
    return ops;
}
