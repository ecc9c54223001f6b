/* 000's approach planning whole (host/planning/bezier000.py plan_000), 000 §III.B.1: P3 the
 * stand-off short of the object on the line to it, the start direction, the control points of
 * eqs. (7)-(11) of every u (control_points.c), the sampling within the ARM9 budget
 * (candidates.c), each curve checked against v <= Vmax, |a_t| <= Amax, R >= R_min (bezier.c)
 * and eq. (9)'s first minimum (the smallest u); the modelled cost as plan_000 charges it. */
#include "plan000.h"

#include "bezier.h"
#include "candidates.h"
#include "control_points.h"
#include "div_round.h"
#include "isqrt.h"
#include "trig.h"

/* bezier000.py SETUP_OPS (the inputs, |P0 P_obj|, the object's direction, P3, the per-plan
 * numbers) and control_points.py CANDIDATE_OPS (one candidate's control points) */
static const mg_ops_t SETUP000 = {0, 0, 2430, 216, 0, 18, 0, 0, 0, 0, 0};
static const mg_ops_t CANDIDATE = {0, 0, 40, 1, 0, 16, 0, 0, 0, 0, 0};
#define DIVS_000 6 /* 64-bit quotients per sample of 000's checks */

void mg_plan000_ctrl(const mg_plan000_t *plan, int32_t i, int32_t *ctrl)
{
    mg_control_point_row(plan->p0_q4, plan->d0_q14, plan->p3_q4, plan->d3_q14, &plan->num,
                         1 + (int64_t)i * plan->stride, ctrl);
}

static void clear(mg_plan000_t *out)
{
    static const mg_plan000_t zero;
    *out = zero;
    out->best = -1;
}

void mg_plan000(const mg_params000_t *p, const int64_t start_q4[2], const int64_t vel_q4[2],
                int has_heading, int32_t heading_mrad, const int64_t target_q4[2],
                mg_plan000_t *out)
{
    clear(out);
    out->ops = SETUP000;
    const int64_t dx = target_q4[0] - start_q4[0], dy = target_q4[1] - start_q4[1];
    const int64_t dist_obj = mg_isqrt64((uint64_t)(dx * dx + dy * dy));
    if (dist_obj <= p->standoff_q4) {
        out->status = MG_PLAN_STANDOFF;
        return;
    }
    mg_unit_q14(dx, dy, out->d3_q14); /* P3 on the line to the object, the stand-off short */
    out->p0_q4[0] = start_q4[0], out->p0_q4[1] = start_q4[1];
    out->p3_q4[0] = target_q4[0] - mg_div_round_i64((int64_t)p->standoff_q4 * out->d3_q14[0],
                                                    1 << MG_DIR_BITS);
    out->p3_q4[1] = target_q4[1] - mg_div_round_i64((int64_t)p->standoff_q4 * out->d3_q14[1],
                                                    1 << MG_DIR_BITS);
    mg_start_direction_q(vel_q4, has_heading, heading_mrad, out->d3_q14, p->moving_q4,
                         out->d0_q14);
    mg_plan_numbers(dist_obj - p->standoff_q4, p->v0_mm_s, p->t_s_ms, &out->num);
    const mg_ops_t one = mg_sample_ops(1, 0, 0, 0, DIVS_000);
    const mg_ops_t none = mg_sample_ops(0, 0, 0, 0, DIVS_000);
    mg_choose_sampling(out->num.n_i, mg_ops_cycles(&one) - mg_ops_cycles(&none),
                       p->budget_us - mg_ops_time_us(&out->ops), p->n_samples_min,
                       p->n_samples_max, &out->n_samples, &out->stride);
    out->n_cand = (int32_t)((out->num.n_i + out->stride - 1) / out->stride);
    out->ops = mg_ops_add(out->ops, mg_ops_scaled(CANDIDATE, out->n_cand));
    for (int32_t i = 0; i < out->n_cand; i++) {
        int32_t ctrl[12], first = 0;
        int64_t len = 0, kint = 0;
        mg_plan000_ctrl(out, i, ctrl);
        const int32_t why = mg_bezier_curve(ctrl, out->n_samples, p->lim, 0, 0, &first, &len,
                                            &kint);
        out->ops = mg_ops_add(out->ops, mg_curve_ops(first, out->n_samples, 0, 0, 0, DIVS_000));
        out->reasons[why]++;
        if (why != MG_OK)
            continue;
        out->n_feasible++;
        const int64_t cost = mg_bezier_cost(p->k1_q16, p->k2_q16, len, kint);
        if (out->best < 0 || cost < out->best_cost_q16) { /* the first minimum: smallest u */
            out->best = i;
            out->best_cost_q16 = cost;
            out->best_len_q4 = len;
            out->best_kint_q16 = kint;
            for (int w = 0; w < 12; w++)
                out->best_ctrl[w] = ctrl[w];
        }
    }
    out->status = out->best < 0 ? MG_PLAN_NONE_FEASIBLE : MG_PLAN_OK;
}

void mg_planner000_start(mg_planner000_t *pl, const mg_params000_t *p, int32_t x_mm,
                         int32_t y_mm, int32_t heading_mrad, int32_t v_mmps,
                         const int32_t obj_xy_mm[2])
{
    const int64_t start[2] = {(int64_t)x_mm * 16, (int64_t)y_mm * 16};
    const int64_t target[2] = {(int64_t)obj_xy_mm[0] * 16, (int64_t)obj_xy_mm[1] * 16};
    const int64_t vel[2] = {mg_div_round_i64((int64_t)v_mmps * mg_cos_q12(heading_mrad), 256),
                            mg_div_round_i64((int64_t)v_mmps * mg_sin_q12(heading_mrad), 256)};
    mg_plan000(p, start, vel, 1, heading_mrad, target, &pl->plan);
    pl->ops = pl->plan.ops;
    pl->traj.n = 0;
    if (pl->plan.status == MG_PLAN_OK
        && mg_trajectory_from_ctrl(pl->plan.best_ctrl, MG_PLAN000_TRAJ_SAMPLES, &pl->traj) == 0)
        pl->ops = mg_ops_add(pl->ops, mg_trajectory_ops(MG_PLAN000_TRAJ_SAMPLES));
    mg_plan_job_start(&pl->job, &pl->ops, MG_PLAN_SLICE_US);
}

mg_ops_t mg_planner000_step(mg_planner000_t *pl, int *done)
{
    const mg_ops_t slice = mg_plan_job_step(&pl->job);
    *done = mg_plan_job_done(&pl->job);
    return slice;
}
