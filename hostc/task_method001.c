/* Paper 001's method: 000's vision with 001's sonar planning and replanning
 * (host/task/method001.py). */
#include "task_method001.h"

#include <string.h>

#include "fixedpoint.h"
#include "task_drive.h"
#include "task_method.h"
#include "task_method000.h"
#include "trig.h"

static mg_state001_t *ms001(mg_task_t *t)
{
    return (mg_state001_t *)(void *)t->ms.bytes;
}

void mg_method001_ms_init(void *ms)
{
    memset(ms, 0, sizeof(mg_state001_t));
    ((mg_state001_t *)ms)->v0_div = 1;
}

void mg_method001_set_replanner(mg_task_t *t, const mg_replanner001_t *rp, void *ctx)
{
    ms001(t)->rp = rp;
    ms001(t)->rp_ctx = ctx;
}

/* TaskParams.for_method("001"): 000's with 001's own (method001.py param_defaults) */
void mg_method001_params(mg_task_params_t *p)
{
    mg_method000_params(p);
    p->h_shoulder_mm = 108;
    p->grasp_r_mm = 120;
    p->grasp_r_tol_mm = 12;
    p->hover_mm = 95;
    p->blind_finish_mm = 250;
    p->max_plan_attempts = 6;
}

static int32_t iabs32(int32_t a)
{
    return a < 0 ? -a : a;
}

int mg_method001_look_first(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    if (t->object_sighted || now_us - t->entered_us >= MG_LOOK_FIRST_US)
        return 0;
    int32_t xy[2];
    mg_task_obj_platform(t, in, xy);
    const int64_t d = mg_isqrt((int64_t)xy[0] * xy[0] + (int64_t)xy[1] * xy[1]);
    if (d < MG_LOOK_FIRST_LO_MM * 16 || d > MG_LOOK_FIRST_HI_MM * 16)
        return 0;
    /* seen from the axle */
    const int32_t bearing = mg_atan2_mrad(xy[0], (int64_t)xy[1] + t->p.mount_forward_mm * 16);
    /* the search's look, the camera high and back */
    const mg_search_params_t *sp = &t->p.search;
    mg_task_set_arm(t, now_us, sp->coarse_theta2_mrad[0], sp->theta3_mrad, sp->theta4_mrad,
                    mg_atan2_mrad(xy[0], xy[1]), 0, 0);
    if (iabs32(bearing) <= t->p.bearing_tol_mrad) {
        t->wheels[0] = t->wheels[1] = 0;
    } else {
        mg_task_turn_in_place(bearing > 0 ? -1 : 1, t->p.turn_wheel_mmps, t->wheels);
    }
    return 1;
}

/* --- APPROACH: eq. (17) with the sonar ring, replanned (section III.E) --------------------- */

static void plan(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, mg_trajectory_t *traj,
                 mg_plan_outcome_t *o)
{
    mg_state001_t *ms = ms001(t);
    if (!ms->rp) {
        o->has_path = 0;
        mg_task_text(o->reason, sizeof o->reason, 0, "no planner");
        return;
    }
    const mg_task_path_t *ps = &t->path;
    if (ms->has_replanner && ps->has_plan_obj && ps->plan_obj_mm[0] == t->obj_mm[0]
        && ps->plan_obj_mm[1] == t->obj_mm[1]) {
        /* same object: the replanner keeps its remembered regions; a plan is asked for with
         * no path followed, so it plans from here even when its last curve looks clear */
        mg_replan001_t dec;
        mg_ops_t ops;
        ms->rp->update(ms->rp_ctx, now_us, in, 1, &dec, traj, o, &ops);
        o->time_us = mg_ops_time_us(&ops);
        return;
    }
    ms->rp->start(ms->rp_ctx, now_us, in, t->obj_mm, ms->v0_div, traj, o);
    ms->has_replanner = 1;
    if (o->has_path) { /* a fallback backs off toward here */
        ms->has_path_from = 1;
        ms->path_from_mm[0] = in->x_mm;
        ms->path_from_mm[1] = in->y_mm;
    }
}

static void start_path(mg_task_t *t, int64_t now_us)
{
    mg_state001_t *ms = ms001(t);
    ms->rp->start_path(ms->rp_ctx, now_us);
}

/* Not while the base turned faster than MG_SIGHTING_MAX_TURN_MRAD_S over the last frame
 * latency: the frame's capture time is known only as frame_latency_us ago, and a sighting
 * taken in a tight turn is tens of mm off (docs/cosim.md "Measured", T2). */
static int sighting_usable(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    int64_t then_us;
    int32_t then[3];
    if (!mg_task_pose_at(t, now_us - t->p.frame_latency_us, &then_us, then))
        return 1;
    const int64_t dt = now_us - then_us > 1 ? now_us - then_us : 1;
    const int64_t turned = iabs32(mg_task_wrap_mrad((int64_t)in->heading_mrad - then[2]));
    return turned * 1000000 / dt <= MG_SIGHTING_MAX_TURN_MRAD_S;
}

/* 001 section III.E: every replan_period_us the sonars check the rest of the path; blocked:
 * replan from here */
static int sonar_replan(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, int moved)
{
    mg_state001_t *ms = ms001(t);
    mg_task_path_t *ps = &t->path;
    if (!(now_us - ps->plan_us >= t->p.replan_period_us && ps->has_follower && !moved
          && ms->has_replanner))
        return -1;
    mg_replan001_t dec;
    mg_plan_outcome_t o;
    mg_ops_t ops;
    memset(&o, 0, sizeof o);
    ms->rp->update(ms->rp_ctx, now_us, in, 0, &dec, &ps->next_traj, &o, &ops);
    if (!dec.has_plan) {
        mg_task_charge(t, &ops);
    } else { /* the plan's time in slices; its path (if any) is taken after the last one */
        mg_task_plan_job_start(t, dec.replanned && o.has_path, o.v_limit_mm_s, 0, o.reason,
                               mg_ops_time_us(&ops));
        mg_task_plan_job_step(t);
    }
    ps->plan_us = now_us;
    if (dec.replanned) {
        ps->plans++;
    } else if (!dec.has_curve) {
        ps->has_follower = 0; /* nothing feasible: stop; the next step plans afresh */
        t->wheels[0] = t->wheels[1] = 0;
        return 1;
    }
    return 0;
}

/* The first plan waits for one full sonar sweep; a new plan is made from standstill. */
static int hold_before_plan(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    const mg_state001_t *ms = ms001(t);
    if (!ms->has_replanner && mg_method001_look_first(t, now_us, in))
        return 1;
    if (!ms->has_replanner && now_us - t->entered_us < t->p.sonar_sweep_us) {
        t->wheels[0] = t->wheels[1] = 0;
        return 1;
    }
    if (!t->path.has_follower && ms->has_replanner
        && (now_us - t->path.plan_us < 500000 || iabs32(in->v_mmps) > 30)) {
        t->wheels[0] = t->wheels[1] = 0; /* stop first, then replan from standstill */
        return 1;
    }
    return 0;
}

/* The close approach's straight way to the object (dist_mm from the waist, to stop
 * grasp_r_mm short) misses the infeasible regions of eq. (16). */
static int straight_clear(mg_task_t *t, const mg_task_inputs_t *in, int32_t dist_mm)
{
    mg_state001_t *ms = ms001(t);
    if (!ms->has_replanner)
        return 0;
    mg_ops_t ops;
    memset(&ops, 0, sizeof ops);
    const int clear = ms->rp->straight_clear(ms->rp_ctx, in, t->obj_mm, dist_mm - t->p.grasp_r_mm,
                                             &ops);
    mg_task_charge(t, &ops);
    return clear;
}

/* An echo straight ahead well short of the object (its own echo is ~170 mm short of the waist
 * distance), or the straight way crossing an infeasible region of eq. (16) (docs/cosim.md
 * "Measured", T1). */
static int way_blocked(mg_task_t *t, const mg_task_inputs_t *in, int32_t dist_mm)
{
    const int32_t n = in->n_sonar;
    const int echo = n >= 3 && 0 < in->sonar_mm[n / 2] && in->sonar_mm[n / 2] < dist_mm - 300;
    return echo || !straight_clear(t, in, dist_mm);
}

static int start_detour(mg_task_t *t, const mg_task_inputs_t *in)
{
    (void)t, (void)in;
    return 0; /* not yet: the fallbacks and detours (method001.py start_detour) */
}

/* 001's ring sees nothing behind the base, so it never backs up: where the follower would
 * reverse it turns on the spot instead and the sonar check replans (docs/cosim.md "Measured",
 * T3). */
static void path_wheels(const mg_wheel_command_t *cmd, int32_t wheels[2])
{
    if ((int64_t)cmd->left_mm_s + cmd->right_mm_s < 0) {
        const int32_t turn = (int32_t)mg_floor_div((int64_t)cmd->right_mm_s - cmd->left_mm_s, 2);
        wheels[0] = -turn;
        wheels[1] = turn;
        return;
    }
    wheels[0] = cmd->left_mm_s;
    wheels[1] = cmd->right_mm_s;
}

/* On the grasp circle (section III.B.1, eqs. (5)-(6); the curve is cut short only with the
 * object at ADJUST's goal, near_margin_mm 0): ROUGH_GRASP looks back at the object
 * with the base still and grasps by eq. (11) of 000 when the look confirms it where the base
 * expected it (method001.py look_decides; the trace's grasp_circle note of the arrival's error
 * is the Python's: l_e is the planner's, not yet in C). */
static void path_end(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, const char *why)
{
    mg_state001_t *ms = ms001(t);
    char text[MG_TASK_WHY];
    (void)in;
    ms->has_circle_expected = 1;
    ms->circle_expected_mm[0] = t->obj_mm[0];
    ms->circle_expected_mm[1] = t->obj_mm[1];
    const size_t n = mg_task_text(text, sizeof text, 0, "on the grasp circle: ");
    mg_task_text(text, sizeof text, n, why);
    mg_task_go(t, now_us, MG_ROUGH_GRASP, text);
}

const mg_path_method_t mg_path001 = {plan, start_path, sighting_usable, sonar_replan,
                                     hold_before_plan, way_blocked, start_detour, path_wheels,
                                     path_end, 0};
