/* Paper 000's method: radial symbol, Bezier path of eq. (9), dual "+", gripper down
 * (host/task/method000.py). */
#include "task_method000.h"

#include <string.h>

#include "task_method.h"
#include "task_sense.h"

static mg_state000_t *ms000(mg_task_t *t)
{
    return (mg_state000_t *)(void *)t->ms.bytes;
}

void mg_method000_ms_init(void *ms)
{
    memset(ms, 0, sizeof(mg_state000_t));
}

void mg_method000_set_planner(mg_task_t *t, mg_planner000_fn planner, void *ctx)
{
    ms000(t)->planner = planner;
    ms000(t)->planner_ctx = ctx;
}

/* TaskParams.for_method("000"): the defaults (000 has none of its own) */
void mg_method000_params(mg_task_params_t *p)
{
    mg_task_params_default(p);
}

int mg_method000_found(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                       const void *radial)
{
    return mg_task_see_object(t, now_us, in, mg_task_sighting_position, radial, 1);
}

void mg_method000_found_why(const mg_task_t *t, char *why, size_t cap)
{
    size_t n = mg_task_text(why, cap, 0, "radial symbol seen, object at (");
    n = mg_task_text_int(why, cap, n, t->obj_mm[0]);
    n = mg_task_text(why, cap, n, ", ");
    n = mg_task_text_int(why, cap, n, t->obj_mm[1]);
    mg_task_text(why, cap, n, ") mm");
}

/* "the mobile platform has to stop until the object is seen again" and the arm searches by
 * Fig. 5 (000 section III.B.2, III.C), theta2 in steps of the paper's d_theta2 from where the
 * camera looked: theta2s gives the camera the pitch alpha it had, in the search posture */
int mg_method000_lost_search(mg_task_t *t, mg_search_params_t *sp, int32_t *theta2s_mrad,
                             int32_t *theta5s_mrad)
{
    const int32_t alpha = t->arm[2] + t->arm[3] + t->arm[4];
    int32_t th2s = alpha - sp->theta3_mrad - sp->theta4_mrad;
    th2s = th2s < sp->theta2_min_mrad ? sp->theta2_min_mrad : th2s;
    th2s = th2s > sp->theta2_max_mrad ? sp->theta2_max_mrad : th2s;
    if (sp->dense_cycles < 1)
        sp->dense_cycles = 1;
    *theta2s_mrad = th2s;
    *theta5s_mrad = t->arm[5];
    return 1;
}

/* "the object searching when lost is similar to ... Fig. 5" (000 section III.C) */
int mg_method000_grasp_lost(mg_task_t *t, int64_t now_us, int64_t waited_us)
{
    mg_state000_t *ms = ms000(t);
    if (ms->grasp_searches >= 1)
        return 0;
    ms->grasp_searches++;
    t->lost_in = MG_PRECISE_GRASP;
    char why[MG_TASK_WHY];
    size_t n = mg_task_text(why, sizeof why, 0, "no spoke seen for ");
    n = mg_task_text_int(why, sizeof why, n, waited_us);
    mg_task_text(why, sizeof why, n, " us at the hover: object lost during the grasp");
    mg_task_go(t, now_us, MG_LOST, why);
    return 1;
}

int32_t mg_method000_grasp_ik(const mg_arm_geometry_t *g, const int32_t target_q4[3],
                              mg_arm_pose_t *pose, int64_t *detail)
{
    return mg_ik_pitch_mm_q4(g, target_q4, MG_ALPHA_DOWN_MRAD, pose, detail);
}

int mg_method000_lowers_hover(void)
{
    return 1;
}

int32_t mg_method000_look_height_mm(const mg_task_params_t *p, int32_t top)
{
    return top ? p->object_top_mm : p->grasp_height_mm;
}

int mg_method000_adjust_done(mg_task_t *t, int64_t now_us, const void *det, int32_t dist_mm)
{
    (void)t, (void)now_us, (void)det, (void)dist_mm;
    return 0; /* the close approach decides (task_adjust.c) */
}

void mg_method000_adjust_goal_mm(const mg_task_t *t, int32_t *goal_mm, int32_t *tol_mm)
{
    *goal_mm = t->p.grasp_r_mm;
    *tol_mm = t->p.grasp_r_tol_mm;
}

int32_t mg_method000_adjust_vmax_mmps(const mg_task_params_t *p)
{
    return p->adjust_vmax_mmps;
}

void mg_method000_enter_approach(mg_task_t *t)
{
    mg_task_enter_path(t);
}

void mg_method000_approach(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                           const mg_sighting_t *radial)
{
    mg_task_follow_path(t, now_us, in, radial);
}

/* --- APPROACH: the path of eq. (9) ---------------------------------------------------------- */

static void plan(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, mg_trajectory_t *traj,
                 mg_plan_outcome_t *o)
{
    const mg_state000_t *ms = ms000(t);
    if (!ms->planner) {
        o->has_path = 0;
        mg_task_text(o->reason, sizeof o->reason, 0, "no planner");
        return;
    }
    const mg_plan000_request_t req = {now_us, in->x_mm, in->y_mm, in->heading_mrad, in->v_mmps,
                                      {t->obj_mm[0], t->obj_mm[1]}, t->p.approach_standoff_mm};
    ms->planner(ms->planner_ctx, &req, traj, o);
}

/* the candidates' rejection reasons (host/planning/bezier_q.py REASONS, bezier.h's codes) in
 * the order of their names, as candidates.py summarize_rejections lists them */
static const char *const REJECTIONS[MG_N_REASONS] = {
    "ok", "time_not_increasing", "speed", "accel", "radius", "grasp_circle", "obstacle",
    "budget", "range"};
static const int32_t BY_NAME[MG_N_REASONS - 1] = {3, 7, 5, 6, 4, 8, 2, 1};

void mg_method000_plan000(void *ctx, const mg_plan000_request_t *req, mg_trajectory_t *traj,
                          mg_plan_outcome_t *o)
{
    mg_plan000_ctx_t *c = (mg_plan000_ctx_t *)ctx;
    mg_params000_t p = c->params;
    p.standoff_q4 = req->standoff_mm * 16;
    mg_planner000_start(&c->pl, &p, req->x_mm, req->y_mm, req->heading_mrad, req->v_mmps,
                        req->obj_mm);
    o->time_us = mg_ops_time_us(&c->pl.ops);
    o->v_limit_mm_s = c->v_limit_mm_s;
    o->has_path = c->pl.traj.n > 0;
    if (o->has_path) {
        memcpy(traj, &c->pl.traj, sizeof *traj);
        mg_task_text(o->reason, sizeof o->reason, 0, REJECTIONS[0]);
        return;
    }
    if (c->pl.plan.status == MG_PLAN_STANDOFF) {
        mg_task_text(o->reason, sizeof o->reason, 0, "already within standoff of the object");
        return;
    }
    size_t n = mg_task_text(o->reason, sizeof o->reason, 0, "no feasible candidate (");
    int32_t listed = 0;
    for (int32_t k = 0; k < MG_N_REASONS - 1; k++) {
        const int32_t count = c->pl.plan.reasons[BY_NAME[k]];
        if (count == 0)
            continue;
        n = mg_task_text(o->reason, sizeof o->reason, n, listed++ ? ", " : "");
        n = mg_task_text(o->reason, sizeof o->reason, n, REJECTIONS[BY_NAME[k]]);
        n = mg_task_text(o->reason, sizeof o->reason, n, ": ");
        n = mg_task_text_int(o->reason, sizeof o->reason, n, count);
    }
    mg_task_text(o->reason, sizeof o->reason, n, ")");
}

static int sighting_usable(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    (void)t, (void)now_us, (void)in;
    return 1;
}

static int sonar_replan(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, int moved)
{
    (void)t, (void)now_us, (void)in, (void)moved;
    return -1; /* 000 plans once (again when the estimate moves); no sonar check */
}

static int hold_before_plan(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    (void)t, (void)now_us, (void)in;
    return 0;
}

static int way_blocked(mg_task_t *t, const mg_task_inputs_t *in, int32_t dist_mm)
{
    (void)t, (void)in, (void)dist_mm;
    return 0;
}

static int start_detour(mg_task_t *t, const mg_task_inputs_t *in)
{
    (void)t, (void)in;
    return 0;
}

static void path_wheels(const mg_wheel_command_t *cmd, int32_t wheels[2])
{
    wheels[0] = cmd->left_mm_s;
    wheels[1] = cmd->right_mm_s;
}

/* 000's vision-based adjustment (section III.B) from here */
static void path_end(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, const char *why)
{
    (void)in;
    mg_task_go(t, now_us, MG_ADJUST, why);
}

const mg_path_method_t mg_path000 = {plan, NULL, sighting_usable, sonar_replan,
                                     hold_before_plan, way_blocked, start_detour, path_wheels,
                                     path_end, 100};
