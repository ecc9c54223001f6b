/* 000's approach planning whole (host/planning/bezier000.py plan_000; bezier000.c is its
 * candidate loop alone, the calibrated kernel): the set-up in integers (control_points.h), the
 * candidate set's sampling (candidates.h), every candidate checked (bezier.h) and the first
 * minimum of eq. (9)'s cost. The candidates are not stored: a
 * candidate's control points are made again from the plan's numbers (mg_plan000_ctrl). */
#ifndef MG_PLAN000_H
#define MG_PLAN000_H

#include <stdint.h>

#include "anytime.h"
#include "budget.h"
#include "control_points.h"
#include "path_follow.h"

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

/* The planner state a method's state embeds (method000.py plan_follower and approach.py's
 * PlanJob): the plan made at once from the task's integers, the reference table of its best
 * curve (MG_PLAN000_TRAJ_SAMPLES samples), and the slices still to charge. */
#define MG_PLAN000_TRAJ_SAMPLES 96
typedef struct {
    mg_plan000_t plan;
    mg_trajectory_t traj; /* traj.n = 0: no curve */
    mg_ops_t ops;         /* the plan's and the table's cost, charged in slices */
    mg_plan_job_t job;
} mg_planner000_t;

/* plan from the pose (mm, mrad, the speed along the heading in mm/s) toward the object (mm):
 * the velocity in the planner's counts is v cos, v sin (Q12) / 256, rounded (drive.py
 * velocity_m); then the job of MG_PLAN_SLICE_US slices */
void mg_planner000_start(mg_planner000_t *pl, const mg_params000_t *p, int32_t x_mm,
                         int32_t y_mm, int32_t heading_mrad, int32_t v_mmps,
                         const int32_t obj_xy_mm[2]);
/* this control step's slice (ARM9 cycles to charge); *done 1 once all are charged: the plan
 * and its table may be used */
mg_ops_t mg_planner000_step(mg_planner000_t *pl, int *done);

#endif
