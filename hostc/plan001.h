/* 001's planning among obstacles whole (host/planning/bezier001.py plan_001; bezier001.c is its
 * coarse pass, the calibrated kernel): the sonar regions of the reading with the remembered
 * ones, less the object's echoes (sonar_regions.c), the end points of eq. (6) facing the start
 * (grasp_circle.c), the control points of eqs. (7)-(11) (control_points.c), the sampling within
 * the ARM9 budget (candidates.c), the coarse pass against the grown regions with its anytime
 * cut, D_m of eq. (18) (clearance.c) of the cheapest coarse-feasible curves as the budget
 * allows, eq. (18)'s pool by cost and its fine check; the modelled cost as plan_001 charges it.
 * Positions in 1/16 mm, the velocity in 1/16 mm per s, headings in mrad. Fixed capacities: the
 * caller gives the work area (mg_plan001_work_t); no allocation, no float. */
#ifndef MG_PLAN001_H
#define MG_PLAN001_H

#include <stdint.h>

#include "budget.h"
#include "control_points.h"
#include "sonar_regions.h"

#define MG_PLAN001_MAX_CAND 4096 /* candidates after the stride */
#define MG_PLAN001_MAX_ENDS 72   /* n_e */
#define MG_PLAN001_MAX_KNOWN 16  /* remembered regions (replan.h MG_REPLAN_MEMORY) */
#define MG_PLAN001_MAX_REGIONS (MG_PLAN001_MAX_KNOWN + MG_SONAR_MAX_REGIONS)
#define MG_PLAN001_MAX_SAMPLES 64 /* n_coarse_max, n_fine */
#define MG_PLAN001_REASONS 9

/* Params001 in integers: v0 (mm/s, the present level's), T_s (ms), k1, k2 (Q16), T_D, the
 * coarse growth, the moving speed, the object-echo tolerance, l_e and the grasp circle's
 * radius squared less its margin (1/16 mm, its square in counts^2), the facing threshold
 * cos_q12(endpoint_max_angle), the sample counts, the budgets (us), expected_cost_fraction in
 * Q16, the limits of bezier.h (true, coarse) and the sonar ring */
typedef struct {
    int32_t v0_mm_s, t_s_ms, k1_q16, k2_q16;
    int64_t t_d_q4, coarse_inflate_q4, moving_q4, echo_tol_q4, l_e_q4, circle_r2;
    int32_t facing_cos_q12, n_e;
    int32_t n_coarse_min, n_coarse_max, n_fine, max_fine;
    int32_t budget_us, total_budget_us, expected_q16;
    int32_t lim[4], lim_coarse[4];
    mg_sonar_cfg_t sonar;
} mg_params001_t;

enum {
    MG_PLAN001_OK = 0,
    MG_PLAN001_ON_CIRCLE = 1,     /* "already on the grasp circle" */
    MG_PLAN001_NONE_FEASIBLE = 2, /* "no feasible candidate (...)" */
    MG_PLAN001_FINE_FAILED = 3,   /* "coarse-feasible candidates failed the fine check (...)" */
    MG_PLAN001_TOO_MANY = 4       /* more candidates than MG_PLAN001_MAX_CAND (none planned) */
};

/* the candidates, kept between the passes, and the regions' words (off the stack) */
typedef struct {
    mg_region_t regions[MG_PLAN001_MAX_REGIONS];
    int64_t geo[3 + 12 * MG_PLAN001_MAX_REGIONS]; /* bezier.h geo */
    int64_t words[11 * MG_PLAN001_MAX_REGIONS];   /* clearance.c's (MG_CLEAR_WORDS) */
    int32_t ctrl[MG_PLAN001_MAX_CAND * 12];
    int32_t reason[MG_PLAN001_MAX_CAND], first[MG_PLAN001_MAX_CAND];
    int64_t cost[MG_PLAN001_MAX_CAND], clear_q4[MG_PLAN001_MAX_CAND];
    int32_t order[MG_PLAN001_MAX_CAND], scratch[MG_PLAN001_MAX_CAND];
} mg_plan001_work_t;

typedef struct {
    int32_t status;                   /* MG_PLAN001_* */
    int32_t n_regions;                /* the regions tested (the object's echoes left out) */
    int32_t n_ends, n_i, n_samples, stride, n_cand, n_feasible;
    int32_t reasons[MG_PLAN001_REASONS]; /* candidates per reason code (bezier.h) */
    int32_t fine_last;                /* the fine check's last reason (-1: none tried) */
    int32_t fine_budget;              /* the fine check stopped for the budget */
    int32_t best;                     /* the chosen candidate (-1: none) */
    int32_t best_ctrl[12];
    mg_ops_t ops;                     /* the modelled ARM9 cost of the plan (Plan.ops) */
} mg_plan001_t;

/* known: the remembered regions (at most MG_PLAN001_MAX_KNOWN), sonar_mm the reading (k_s) */
void mg_plan001(const mg_params001_t *p, const int64_t start_q4[2], const int64_t vel_q4[2],
                int32_t heading_mrad, const int64_t target_q4[2], const int32_t *sonar_mm,
                const mg_region_t *known, int32_t n_known, mg_plan001_work_t *work,
                mg_plan001_t *out);
/* plan_001's reason as text (Plan.reason) into buf (cap bytes, 0-terminated) */
void mg_plan001_reason(const mg_plan001_t *plan, char *buf, int32_t cap);

#endif
