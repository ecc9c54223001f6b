/* 000's approach planning whole (host/planning/bezier000.py plan_000; bezier000.c is its
 * candidate loop alone, the calibrated kernel): the set-up in integers (control_points.h), the
 * candidate set's sampling (candidates.h), every candidate checked (bezier.h) and the first
 * minimum of eq. (9)'s cost. The candidates are not stored: a
 * candidate's control points are made again from the plan's numbers (mg_plan000_ctrl). */
#ifndef MG_PLAN000_H
#define MG_PLAN000_H

#include <stdint.h>

#include "budget.h"
#include "control_points.h"

/* Params000 in integers: T_s (ms), v0 (mm/s), the stand-off and the moving speed (1/16 mm,
 * 1/16 mm per s), the sample counts, the ARM9 budget (us), k1, k2 (Q16) and the limits of
 * bezier.h (v_max, a_max, kappa_max in Q16, 0: 000's |dv/dt|) */
typedef struct {
    int32_t t_s_ms, v0_mm_s, standoff_q4, moving_q4;
    int32_t n_samples_min, n_samples_max, budget_us;
    int32_t k1_q16, k2_q16;
    int32_t lim[4];
} mg_params000_t;

enum { MG_PLAN_OK = 0, MG_PLAN_STANDOFF = 1, MG_PLAN_NONE_FEASIBLE = 2 };

#define MG_N_REASONS 9

typedef struct {
    int32_t status;     /* MG_PLAN_* */
    int32_t n_samples, stride;
    int32_t n_cand;     /* candidates evaluated: u = 1, 1 + stride, ... <= N_i */
    int32_t n_feasible;
    int32_t best;       /* index of the chosen candidate (u = 1 + best stride), -1: none */
    int32_t reasons[MG_N_REASONS]; /* candidates per reason code of bezier.h */
    int32_t best_ctrl[12];
    int64_t best_cost_q16;
    int64_t best_len_q4, best_kint_q16;
    mg_plan_numbers_t num;
    int64_t p0_q4[2], p3_q4[2];
    int32_t d0_q14[2], d3_q14[2];
    mg_ops_t ops;       /* the modelled ARM9 cost of the plan (Plan.ops) */
} mg_plan000_t;

/* positions in 1/16 mm, the velocity in 1/16 mm per s, the heading in mrad (has_heading 0:
 * none given) */
void mg_plan000(const mg_params000_t *p, const int64_t start_q4[2], const int64_t vel_q4[2],
                int has_heading, int32_t heading_mrad, const int64_t target_q4[2],
                mg_plan000_t *out);
/* the control points (12 words) of candidate i of a plan (i < out->n_cand) */
void mg_plan000_ctrl(const mg_plan000_t *plan, int32_t i, int32_t *ctrl);

#endif
