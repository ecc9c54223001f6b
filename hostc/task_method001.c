/* Paper 001's method: 000's vision with 001's sonar planning and replanning
 * (host/task/method001.py). */
#include "task_method001.h"

#include <string.h>

#include "bezier.h"
#include "escape.h"
#include "fixedpoint.h"
#include "grasp_circle.h"
#include "json.h"
#include "kernels.h"
#include "path_follow.h"
#include "sonar_guard.h"
#include "task_drive.h"
#include "task_grasp.h"
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

static int32_t circle_l_e_mm(mg_task_t *t);

void mg_method001_set_replanner(mg_task_t *t, const mg_replanner001_t *rp, void *ctx)
{
    ms001(t)->rp = rp;
    ms001(t)->rp_ctx = ctx;
    (void)circle_l_e_mm(t); /* at start-up: its scan of eq. (5) in no control step */
}

/* TaskParams.for_method("001"): the defaults with 001's own (method001.py param_defaults; not
 * 000's wander) */
void mg_method001_params(mg_task_params_t *p)
{
    mg_task_params_default(p);
    p->h_shoulder_mm = 108;
    p->grasp_r_mm = 120;
    p->grasp_r_tol_mm = 12;
    p->hover_mm = 95;
    p->blind_finish_mm = 250;
    p->max_plan_attempts = 6;
}

/* the search's look-around here is over, nothing is being confirmed or driven to, the object
 * was never seen by the camera (or not since a blind grasp on its estimate found no evidence) and
 * its estimate is within MG_UNSEEN_NEAR_MM of the axle (method001.py unseen_near) */
static int unseen_near(const mg_task_t *t, const mg_task_inputs_t *in)
{
    if (t->object_sighted || !t->has_obj || t->has_confirm_until || t->far_phase /* 0: none */
        || t->search.cycle < t->search.p.turns_per_wander)
        return 0;
    const int64_t dx = (int64_t)t->obj_mm[0] - in->x_mm;
    const int64_t dy = (int64_t)t->obj_mm[1] - in->y_mm;
    return dx * dx + dy * dy <= (int64_t)MG_UNSEEN_NEAR_MM * MG_UNSEEN_NEAR_MM;
}

int mg_method001_search_back_off(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    static const mg_back_off_rule_t rule = {MG_BACK_OFFS_001, 0, MG_CUT_WAIT_US,
                                            MG_CUT_STALE_US, MG_CUT_AWAY_MM};
    mg_cut_back_off_t *bo = &ms001(t)->cut;
    if (bo->phase == MG_BACK_OFF000_NONE && bo->back_offs < rule.max && unseen_near(t, in)) {
        /* the same move off the estimate (method001.py search_back_off) */
        const int64_t dx = (int64_t)t->obj_mm[0] - in->x_mm;
        const int64_t dy = (int64_t)t->obj_mm[1] - in->y_mm;
        const int32_t turn = mg_task_wrap_mrad((int64_t)mg_atan2_mrad(dy, dx) - in->heading_mrad);
        bo->back_offs++;
        mg_back_off_away(bo, in, turn, rule.away_mm);
        bo->has_cut_first = 0; /* a cut seen from here says nothing of the next place */
        static const char *const names[3] = {"dist_mm", "n", "turn_mrad"};
        const int64_t values[3] = {mg_isqrt(dx * dx + dy * dy), bo->back_offs, turn};
        mg_task_note_ints(t, "back_off_unseen", 3, names, values);
    }
    return mg_search_back_off(t, now_us, in, bo, &rule);
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

/* the board's replanner's state, or NULL (a caller's replanner: its curve is its own) */
static const mg_board_replanner001_t *board_of(const mg_state001_t *ms)
{
    return ms->rp == &mg_board_replanner001 ? (const mg_board_replanner001_t *)ms->rp_ctx : NULL;
}

/* the plan's trace detail (method001.py plan: start_001's detail, or update_001's reason and
 * curve); start: with the plan's candidates, the feasible ones and its modelled ARM9 time */
static void note_plan(mg_task_t *t, const mg_board_replanner001_t *b, int start,
                      const char *reason)
{
    char text[2 * MG_TASK_NOTE_BYTES + MG_PLAN_REASON]; /* the curve and the reason */
    mg_json_t j;
    mg_json_init(&j, text, sizeof text - 1);
    mg_json_begin_object(&j);
    if (start ? b->plan.status == MG_PLAN001_OK : b->st.has_curve) {
        mg_json_key(&j, "best_ctrl");
        mg_method000_json_ctrl(&j, start ? b->plan.best_ctrl : b->st.ctrl);
    }
    if (start) {
        mg_json_key(&j, "candidates");
        mg_json_int(&j, b->plan.n_cand);
        mg_json_key(&j, "feasible");
        mg_json_int(&j, b->plan.n_feasible);
        mg_json_key(&j, "plan_arm9_us");
        mg_json_int(&j, mg_ops_time_us(&b->plan.ops));
    }
    mg_json_key(&j, "planner");
    mg_json_string(&j, "001", 3);
    mg_json_key(&j, "reason");
    mg_json_string(&j, reason, strlen(reason));
    mg_json_end_object(&j);
    if (j.overflow) { /* counted, never silent */
        t->notes_lost++;
        return;
    }
    mg_json_terminate(&j);
    mg_task_note(t, "plan", text);
}

/* the sonar check's replan detail: its reason as a JSON string */
static void note_replan(mg_task_t *t, const char *reason)
{
    char text[MG_PLAN_REASON + 16];
    mg_json_t j;
    mg_json_init(&j, text, sizeof text - 1);
    mg_json_string(&j, reason, strlen(reason));
    mg_json_terminate(&j);
    mg_task_note(t, "replan", text);
}

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
        if (board_of(ms))
            note_plan(t, board_of(ms), 0, o->reason);
        return;
    }
    ms->rp->start(ms->rp_ctx, now_us, in, t->obj_mm, ms->v0_div, traj, o);
    ms->has_replanner = 1;
    if (board_of(ms))
        note_plan(t, board_of(ms), 1, o->reason);
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
        note_replan(t, o.reason);
        if (board_of(ms))
            note_plan(t, board_of(ms), 0, o.reason);
    } else if (dec.blocked && dec.has_curve) {
        note_replan(t, o.reason); /* blocked far ahead, no update yet: path kept */
    } else if (!dec.has_curve) {
        ps->has_follower = 0; /* nothing feasible: stop; the next step plans afresh */
        note_replan(t, o.reason);
        t->wheels[0] = t->wheels[1] = 0;
        return 1;
    }
    return 0;
}

/* The first plan waits for one full sonar sweep; a detour is driven to its end; a new plan is
 * made from standstill. */
static int hold_before_plan(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    mg_state001_t *ms = ms001(t);
    if (!ms->has_replanner && mg_method001_look_first(t, now_us, in))
        return 1;
    if (!ms->has_replanner && now_us - t->entered_us < t->p.sonar_sweep_us) {
        t->wheels[0] = t->wheels[1] = 0;
        return 1;
    }
    if (ms->detour.active) {
        if (!mg_drive_detour(t, in, &ms->detour))
            return 1;
        ms->detour.active = 0; /* done: stop, then plan afresh from here */
        t->path.plan_us = now_us;
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

/* the detour's heading (method001.py detour_heading): the escape's when it found one clear of
 * the infeasible regions, else the free sonar direction nearest the object's bearing; with none
 * free a quarter turn left, not driven (the next sonar sweep decides again) */
static void detour_heading(const mg_task_t *t, const mg_task_inputs_t *in, int found,
                           int32_t head_mrad, mg_detour_t *d)
{
    memset(d, 0, sizeof *d);
    d->active = 1;
    d->length_mm = t->p.detour_mm;
    if (found) {
        d->heading_mrad = mg_task_wrap_mrad(head_mrad);
        d->drive = d->checked = 1;
        return;
    }
    d->drive = mg_free_heading_nearest(in, t->obj_mm, t->p.detour_clear_mm, &d->heading_mrad);
    if (!d->drive)
        d->heading_mrad = mg_task_wrap_mrad((int64_t)in->heading_mrad + 1571);
}

/* the trace's fallback and detour detail (method001.py start_detour's notes) */
static void note_fallback(mg_task_t *t, const char *step, int32_t n)
{
    char text[MG_TASK_NOTE_BYTES];
    mg_json_t j;
    mg_json_init(&j, text, sizeof text - 1);
    mg_json_begin_object(&j);
    mg_json_key(&j, "n");
    mg_json_int(&j, n);
    mg_json_key(&j, "step");
    mg_json_string(&j, step, strlen(step));
    mg_json_end_object(&j);
    mg_json_terminate(&j);
    mg_task_note(t, "fallback", text);
}

static void note_detour(mg_task_t *t, const mg_detour_t *d, int32_t count)
{
    char text[MG_TASK_NOTE_BYTES];
    mg_json_t j;
    mg_json_init(&j, text, sizeof text - 1);
    mg_json_begin_object(&j);
    if (d->checked) {
        mg_json_key(&j, "checked");
        mg_json_bool(&j, 1);
    }
    mg_json_key(&j, "drive");
    mg_json_bool(&j, d->drive);
    mg_json_key(&j, "from");
    mg_json_null(&j);
    mg_json_key(&j, "heading_mrad");
    mg_json_int(&j, d->heading_mrad);
    mg_json_end_object(&j);
    mg_json_terminate(&j);
    mg_task_note(t, "detour", text);
    mg_task_note_int(t, "detour_count", count);
}

/* Obstacles across the way and no feasible curve from here: fall back in steps (each a
 * fallback detail), then plan again: a lower v0 (the slower end speed of eq. (9) gives the
 * candidates more room under A_max), a short back-off toward where the last path began, a turn
 * in place toward the widest free sonar sector, then drives aside through free sonar space
 * (escape_001, at most max_detours); the last step repeated (method001.py FALLBACKS). */
static int start_detour(mg_task_t *t, const mg_task_inputs_t *in)
{
    enum { LOWER_V0, BACK_OFF, WIDEST_SECTOR, DETOUR };
    static const char *const STEP[] = {"lower_v0", "back_off", "widest_sector", "detour"};
    mg_state001_t *ms = ms001(t);
    const int32_t step = ms->fallbacks < DETOUR ? ms->fallbacks : DETOUR;
    if (step == DETOUR && ms->detours >= t->p.max_detours)
        return 0;
    ms->fallbacks++;
    note_fallback(t, STEP[step], ms->fallbacks);
    mg_detour_t *d = &ms->detour;
    if (step == LOWER_V0) {
        ms->v0_div *= 2;
        ms->has_replanner = 0; /* planned afresh with the lower v0 */
        return 1;
    }
    if (step == WIDEST_SECTOR) {
        memset(d, 0, sizeof *d);
        d->active = 1;
        d->heading_mrad = mg_widest_free_heading(in, t->p.detour_clear_mm);
        d->length_mm = t->p.detour_mm;
        return 1;
    }
    if (step == BACK_OFF) {
        /* facing (and driving, the sonars watching) back toward where the last path began */
        const int64_t fx = ms->has_path_from ? ms->path_from_mm[0] : in->x_mm;
        const int64_t fy = ms->has_path_from ? ms->path_from_mm[1] : in->y_mm;
        const int64_t dx = fx - in->x_mm, dy = fy - in->y_mm;
        if (dx * dx + dy * dy < (int64_t)MG_BACK_OFF_MM * MG_BACK_OFF_MM)
            return start_detour(t, in); /* nowhere to back off to: the next step */
        memset(d, 0, sizeof *d);
        d->active = d->drive = 1;
        d->heading_mrad = mg_atan2_mrad(dy, dx);
        d->length_mm = MG_BACK_OFF_MM;
        return 1;
    }
    ms->detours++;
    int32_t head = 0;
    mg_ops_t ops;
    memset(&ops, 0, sizeof ops);
    const int found = ms->rp->escape(ms->rp_ctx, in, t->obj_mm, t->p.detour_mm, ms->detour_side,
                                     &head, &ops);
    mg_task_charge(t, &ops);
    if (found && !ms->detour_side) { /* keep to the first one's side */
        const int32_t off = mg_task_wrap_mrad(
            (int64_t)head - mg_atan2_mrad((int64_t)t->obj_mm[1] - in->y_mm,
                                          (int64_t)t->obj_mm[0] - in->x_mm));
        ms->detour_side = (off > 0) - (off < 0);
    }
    detour_heading(t, in, found, head, d);
    note_detour(t, d, ms->detours);
    return 1;
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

/* l_e of eq. (5) for the object's grasp point (planner_params_001's arm, grasp_height_mm):
 * (l_m + l_n) / 2 to the mm, as Python rounds it (no tie for grasp heights of 0-399 mm); 0
 * when out of reach. Once a run, with the replanner: a scan of eq. (5)'s grid, start-up work
 * (as the board replanner's l_e, config.c), not a control step's. */
static int32_t circle_l_e_mm(mg_task_t *t)
{
    mg_state001_t *ms = ms001(t);
    int64_t l_um[2];
    if (!ms->has_l_e) {
        ms->has_l_e = 1;
        if (mg_grasp_radius001_um(t->p.grasp_height_mm, l_um) == 0) {
            ms->l_e_mm = (int32_t)mg_div_even64(l_um[0] + l_um[1], 2000);
        }
    }
    return ms->l_e_mm;
}

static int32_t axle_mm(const mg_task_t *t, const mg_task_inputs_t *in)
{
    const int64_t dx = (int64_t)t->obj_mm[0] - in->x_mm, dy = (int64_t)t->obj_mm[1] - in->y_mm;
    return (int32_t)mg_isqrt(dx * dx + dy * dy);
}

/* On the grasp circle (section III.B.1, eqs. (5)-(6), l_e for the object's grasp height; the
 * curve is cut short only with the object at ADJUST's goal, near_margin_mm 0, or 60 mm from the
 * footprint once braked, object_clear_mm): the base stops,
 * ROUGH_GRASP looks back at the object and grasps by eq. (11) of 000 when the look confirms it
 * where the base expected it (mg_method001_look_decides). The arrival's error, the axle's
 * distance from the estimate less l_e, goes in the trace (grasp_circle; a start already on
 * the circle has no path and no path_error_mm). */
static void path_end(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, const char *why,
                     const int32_t *error_mm)
{
    mg_state001_t *ms = ms001(t);
    const int32_t l_e = circle_l_e_mm(t), axle = axle_mm(t, in);
    int32_t xy[2];
    mg_task_obj_platform(t, in, xy);
    char text[MG_TASK_NOTE_BYTES];
    mg_json_t j;
    mg_json_init(&j, text, sizeof text - 1);
    mg_json_begin_object(&j);
    mg_json_key(&j, "axle_mm");
    mg_json_int(&j, axle);
    mg_json_key(&j, "error_mm");
    mg_json_int(&j, axle - l_e);
    mg_json_key(&j, "l_e_mm");
    mg_json_int(&j, l_e);
    mg_json_key(&j, "path_error_mm");
    if (error_mm)
        mg_json_int(&j, *error_mm);
    else
        mg_json_null(&j);
    mg_json_key(&j, "waist_mm");
    mg_json_int(&j, mg_isqrt((int64_t)xy[0] * xy[0] + (int64_t)xy[1] * xy[1]) / 16);
    mg_json_end_object(&j);
    mg_json_terminate(&j);
    mg_task_note(t, "grasp_circle", text);
    ms->has_circle_expected = 1;
    ms->circle_expected_mm[0] = t->obj_mm[0];
    ms->circle_expected_mm[1] = t->obj_mm[1];
    ms->circle_l_e_mm = l_e;
    ms->circle_adjusts = t->sight_adjusts;
    char reason[MG_TASK_WHY];
    const size_t n = mg_task_text(reason, sizeof reason, 0, "on the grasp circle: ");
    mg_task_text(reason, sizeof reason, n, why);
    mg_task_go(t, now_us, MG_ROUGH_GRASP, reason);
}

int mg_method001_look_decides(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    mg_state001_t *ms = ms001(t);
    const struct mg_task_method *r = t->rules;
    if (!ms->has_circle_expected)
        return 0;
    ms->has_circle_expected = 0;
    if (t->sight_adjusts != ms->circle_adjusts)
        return 0; /* the base closed in since the arrival: 000's grasp from here */
    const int64_t ex = (int64_t)t->obj_mm[0] - ms->circle_expected_mm[0];
    const int64_t ey = (int64_t)t->obj_mm[1] - ms->circle_expected_mm[1];
    const int32_t off_mm = (int32_t)mg_isqrt(ex * ex + ey * ey);
    char why[MG_TASK_WHY];
    size_t n = 0;
    int32_t grasp[3] = {0, 0, 0};
    mg_arm_pose_t down, pre;
    memset(&down, 0, sizeof down);
    memset(&pre, 0, sizeof pre);
    if (!t->sight_frames) {
        n = mg_task_text(why, sizeof why, 0, "not seen by the look");
    } else if (off_mm > MG_CIRCLE_CONFIRM_MM) {
        n = mg_task_text(why, sizeof why, 0, "seen ");
        n = mg_task_text_int(why, sizeof why, n, off_mm);
        n = mg_task_text(why, sizeof why, n, " mm from where expected");
    } else {
        int64_t down_detail, pre_detail;
        mg_task_object_target_q4(t, in, t->p.grasp_height_mm, 0, grasp);
        const int32_t down_code = r->grasp_ik(&t->geom, grasp, &down, &down_detail);
        int32_t pre_code = -1; /* none tried */
        /* the gripper goes down from CIRCLE_PRE_MM above the grasp point, the first reachable
         * in 10 mm steps down to the object's top */
        for (int32_t up_mm = MG_CIRCLE_PRE_MM;
             up_mm > t->p.object_top_mm - t->p.grasp_height_mm - 1; up_mm -= 10) {
            const int32_t above[3] = {grasp[0], grasp[1], grasp[2] + up_mm * 16};
            pre_code = r->grasp_ik(&t->geom, above, &pre, &pre_detail);
            if (pre_code == MG_IK_OK)
                break;
        }
        if (down_code != MG_IK_OK) {
            n = mg_task_text(why, sizeof why, 0, "grasp point out of reach: ");
            n = mg_task_ik_reason(&t->geom, down_code, down_detail, &down, why, sizeof why, n);
        } else if (pre_code != MG_IK_OK) {
            n = mg_task_text(why, sizeof why, 0, "no reachable pose above the grasp point");
        }
    }
    /* the arrival's error as the look sees it: the axle's distance from the sighted object
     * less l_e (the base stood still since the arrival) */
    {
        char text[MG_TASK_NOTE_BYTES];
        mg_json_t j;
        mg_json_init(&j, text, sizeof text - 1);
        mg_json_begin_object(&j);
        mg_json_key(&j, "confirmed");
        mg_json_bool(&j, n == 0);
        mg_json_key(&j, "error_mm");
        mg_json_int(&j, axle_mm(t, in) - ms->circle_l_e_mm);
        mg_json_key(&j, "frames");
        mg_json_int(&j, t->sight_frames);
        mg_json_key(&j, "off_mm");
        mg_json_int(&j, off_mm);
        mg_json_end_object(&j);
        mg_json_terminate(&j);
        mg_task_note(t, "circle_look", text);
    }
    if (n == 0) {
        ms->ik_grasp = 1;
        t->has_grasp_xy = 1;
        t->grasp_xy_q4[0] = grasp[0], t->grasp_xy_q4[1] = grasp[1];
        t->grasp_alpha_mrad = pre.theta2_mrad + pre.theta3_mrad + pre.theta4_mrad;
        t->phase = MG_PHASE_NONE;
        mg_task_apply_pose(t, now_us, &pre, 0, 0);
        mg_task_note_pose(t, "ik_pre_pose_mrad", &pre);
        return 1;
    }
    char reason[MG_TASK_WHY];
    size_t k = mg_task_text(reason, sizeof reason, 0,
                            "the look from the grasp circle did not confirm the object (");
    k = mg_task_text(reason, sizeof reason, k, why);
    mg_task_text(reason, sizeof reason, k,
                 "): vision-based adjustment and precise grasp");
    mg_task_go(t, now_us, MG_ADJUST, reason);
    return 1;
}

void mg_method001_enter_precise(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    mg_state001_t *ms = ms001(t);
    if (!ms->ik_grasp) {
        ms->has_circle_expected = 0;
        mg_method000_enter_precise(t, now_us, in);
        return;
    }
    ms->ik_grasp = 0;
    mg_task_descend(t, now_us, "eq. (11) from the grasp circle, the object confirmed by the look",
                    "ik");
}

/* Last line of the no-contact rule (001 section III.C.2, R_r): the object's own echo does
 * not count. In APPROACH a plan from standstill starts forward, into the echo, and was stopped
 * again at once, and so did a plan from the turned pose and the detours: the base first turns
 * toward the widest free sector and drives out of R_r before it plans again. */
mg_ops_t mg_method001_follow_ops(void)
{
    /* method001.py FOLLOW_OPS: the look at the object, two 64-bit roots, the follower's step */
    const mg_ops_t ops = {0, 0, 5154, 486, 14, 38, 2, 28, 0, 0, 0};
    return ops;
}

mg_ops_t mg_method001_guard_sonar_ops(void)
{
    /* method001.py GUARD_SONAR_OPS: one sonar of the ring looked at by the guard */
    const mg_ops_t ops = {0, 0, 8, 2, 0, 0, 1, 0, 0, 0, 0};
    return ops;
}

void mg_method001_guard_wheels(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    mg_state001_t *ms = ms001(t);
    int32_t phi, rng;
    if ((int64_t)t->wheels[0] + t->wheels[1] > 0 && in->n_sonar >= 2) {
        const mg_ops_t ops = mg_ops_scaled(mg_method001_guard_sonar_ops(), in->n_sonar);
        mg_task_charge(t, &ops);
    }
    mg_close_guard(t, now_us, in);
    if (!mg_guard_stop(t, in, &phi, &rng))
        return;
    if (t->state != MG_APPROACH) {
        mg_note_sonar_guard(t, phi, rng, NULL);
        return;
    }
    mg_out_of_r_r(t, in, &ms->detour);
    mg_note_sonar_guard(t, phi, rng, &ms->detour);
}

const mg_path_method_t mg_path001 = {plan, start_path, sighting_usable, sonar_replan,
                                     hold_before_plan, way_blocked, start_detour, path_wheels,
                                     path_end, 0, 60, mg_method001_follow_ops};

/* --- the board's replanner (method001.py start_001, update_001, straight_clear_001) -------- */

#define TRAJ_SAMPLES_001 96 /* path_follow.py Trajectory.from_curve */

/* Python's f"{q4 / 16000:.2f}" (q4 >= 0, < 2^40): the double nearest q4 / 16000 rounded to
 * hundredths; a tie in decimals goes the way the double lies off it, an exact one to even */
size_t mg_method001_text_m_2(char *out, size_t cap, size_t at, int64_t q4)
{
    int64_t hundredths = q4 / 160;
    if (q4 % 160 > 80) {
        hundredths++;
    } else if (q4 % 160 == 80) {
        /* the double's mantissa m = q4 2^s / 16000 rounded, m in [2^52, 2^53) */
        int32_t s = 0;
        while (s < 52 ? (52 - s > 48 || q4 < ((int64_t)16000 << (52 - s)))
                      : (q4 << (s - 52)) < 16000)
            s++;
        int64_t t = q4 % 32000; /* q4 2^s mod 32000: the remainder and the floor's parity */
        for (int32_t i = 0; i < s; i++)
            t = t * 2 % 32000;
        const int64_t r = t % 16000;
        const int up = 2 * r > 16000 || (2 * r == 16000 && t >= 16000);
        if (r != 0 ? up : (hundredths & 1))
            hundredths++;
    }
    at = mg_task_text_int(out, cap, at, hundredths / 100);
    at = mg_task_text(out, cap, at, hundredths % 100 < 10 ? ".0" : ".");
    return mg_task_text_int(out, cap, at, hundredths % 100);
}

static void board_pose(const mg_task_inputs_t *in, int64_t p_q4[2], int64_t vel_q4[2])
{
    p_q4[0] = (int64_t)in->x_mm * 16;
    p_q4[1] = (int64_t)in->y_mm * 16;
    vel_q4[0] = mg_div_round64((int64_t)in->v_mmps * mg_cos_q12(in->heading_mrad), 256);
    vel_q4[1] = mg_div_round64((int64_t)in->v_mmps * mg_sin_q12(in->heading_mrad), 256);
}

/* plan_001 from the pose with the memory, v0 by the level; the plan's ops */
static void board_plan(mg_board_replanner001_t *b, const mg_task_inputs_t *in)
{
    int64_t p[2], vel[2];
    board_pose(in, p, vel);
    /* halves to even: the Python's round(v0 / v0_div * factor * 1000), the divisions powers of
     * two (a half-even rounding of a half-even rounding by powers of two is the single one) */
    b->params.v0_mm_s = (int32_t)mg_div_even64(b->level_v0_mm_s[b->st.level], b->v0_div);
    mg_plan001(&b->params, p, vel, in->heading_mrad, b->cfg.target_q4, in->sonar_mm,
               b->st.memory, b->st.n_memory, &b->work, &b->plan);
}

/* the new curve's reference table: the path and its ops */
static mg_ops_t board_path(const mg_board_replanner001_t *b, mg_trajectory_t *traj,
                           mg_plan_outcome_t *o)
{
    static const mg_ops_t none;
    o->has_path = 0;
    o->v_limit_mm_s = b->v_limit_mm_s;
    if (!b->st.has_curve || mg_trajectory_from_ctrl(b->st.ctrl, TRAJ_SAMPLES_001, traj) != 0)
        return none;
    o->has_path = 1;
    return mg_trajectory_ops(TRAJ_SAMPLES_001);
}

static void board_start(void *ctx, int64_t now_us, const mg_task_inputs_t *in,
                        const int32_t obj_mm[2], int32_t v0_div, mg_trajectory_t *traj,
                        mg_plan_outcome_t *o)
{
    mg_board_replanner001_t *b = ctx;
    b->cfg.target_q4[0] = (int64_t)obj_mm[0] * 16;
    b->cfg.target_q4[1] = (int64_t)obj_mm[1] * 16;
    b->v0_div = v0_div > 0 ? v0_div : 1;
    mg_replan001_init(&b->st);
    board_plan(b, in);
    const int has = b->plan.status == MG_PLAN001_OK;
    mg_replan001_adopt(&b->cfg, &b->st, now_us, (int64_t)in->x_mm * 16, (int64_t)in->y_mm * 16,
                       in->heading_mrad, in->sonar_mm, has, b->plan.best_ctrl);
    mg_plan001_reason(&b->plan, o->reason, (int32_t)sizeof o->reason);
    const mg_ops_t ops = mg_ops_add(b->plan.ops, board_path(b, traj, o));
    o->time_us = mg_ops_time_us(&ops);
}

static void board_update(void *ctx, int64_t now_us, const mg_task_inputs_t *in, int32_t force,
                         mg_replan001_t *dec, mg_trajectory_t *traj, mg_plan_outcome_t *o,
                         mg_ops_t *ops)
{
    static const char *const WHY[] = {"blocked", "no path", "path dropped"};
    mg_board_replanner001_t *b = ctx;
    const int64_t px = (int64_t)in->x_mm * 16, py = (int64_t)in->y_mm * 16;
    mg_replan001_check_t chk;
    o->has_path = 0;
    o->v_limit_mm_s = b->v_limit_mm_s;
    const int need = mg_replan001_check(&b->cfg, &b->st, now_us, px, py, in->heading_mrad,
                                        in->sonar_mm, force, &chk);
    dec->blocked = chk.blocked;
    dec->replanned = 0;
    dec->has_curve = b->st.has_curve;
    dec->has_plan = need;
    *ops = chk.ops;
    if (!need) {
        mg_task_text(o->reason, sizeof o->reason, 0, "path clear");
        o->time_us = mg_ops_time_us(ops);
        return;
    }
    board_plan(b, in);
    int32_t why = 0;
    int64_t ahead = -1;
    const int got = mg_replan001_after_plan(&b->cfg, &b->st, now_us, px, py, in->heading_mrad,
                                            in->sonar_mm, &chk, b->plan.status == MG_PLAN001_OK,
                                            b->plan.best_ctrl, &why, &ahead);
    char reason[MG_PLAN_REASON];
    mg_plan001_reason(&b->plan, reason, (int32_t)sizeof reason);
    *ops = mg_ops_add(*ops, b->plan.ops);
    dec->replanned = got == MG_REPLAN_NEW;
    dec->has_curve = got != MG_REPLAN_STOP;
    size_t at = 0;
    if (got == MG_REPLAN_KEPT) {
        at = mg_task_text(o->reason, sizeof o->reason, 0, "blocked ");
        at = mg_method001_text_m_2(o->reason, sizeof o->reason, at, ahead);
        at = mg_task_text(o->reason, sizeof o->reason, at, " m ahead, no update yet (");
        at = mg_task_text(o->reason, sizeof o->reason, at, reason);
        mg_task_text(o->reason, sizeof o->reason, at, "): path kept");
    } else {
        at = mg_task_text(o->reason, sizeof o->reason, 0, WHY[why]);
        at = mg_task_text(o->reason, sizeof o->reason, at, ": ");
        mg_task_text(o->reason, sizeof o->reason, at, got == MG_REPLAN_NEW ? "replanned" : reason);
    }
    if (got == MG_REPLAN_NEW)
        *ops = mg_ops_add(*ops, board_path(b, traj, o));
    o->time_us = mg_ops_time_us(ops);
}

static void board_start_path(void *ctx, int64_t now_us)
{
    mg_board_replanner001_t *b = ctx;
    mg_replan001_start_path(&b->st, now_us);
}

static int board_straight_clear(void *ctx, const mg_task_inputs_t *in, const int32_t obj_mm[2],
                                int32_t travel_mm, mg_ops_t *ops)
{
    static const mg_ops_t none;
    enum { PER = MG_GEO_HEAD + MG_REGION_WORDS };
    mg_board_replanner001_t *b = ctx;
    mg_region_t regions[MG_SONAR_MAX_REGIONS + MG_REPLAN_MEMORY];
    int64_t geo[PER * (MG_SONAR_MAX_REGIONS + MG_REPLAN_MEMORY)];
    int64_t clear[MG_CLEAR_WORDS * (MG_SONAR_MAX_REGIONS + MG_REPLAN_MEMORY)];
    const int64_t px = (int64_t)in->x_mm * 16, py = (int64_t)in->y_mm * 16;
    *ops = none;
    if (travel_mm <= 0)
        return 1;
    int32_t n = mg_replan001_fresh(&b->cfg, px, py, in->heading_mrad, in->sonar_mm, regions);
    for (int32_t i = 0; i < b->st.n_memory; i++)
        regions[n++] = b->st.memory[i];
    for (int32_t r = 0; r < n; r++) {
        geo[PER * r] = geo[PER * r + 1] = geo[PER * r + 2] = 0;
        mg_region_geo(&regions[r], geo + PER * r + MG_GEO_HEAD);
        mg_region_clear(&regions[r], clear + MG_CLEAR_WORDS * r);
    }
    const int32_t toward = mg_atan2_mrad((int64_t)obj_mm[1] - in->y_mm,
                                         (int64_t)obj_mm[0] - in->x_mm);
    const int ok = mg_segment_clear_q(geo, clear, n, px, py, toward, (int64_t)travel_mm * 16, 16,
                                      0, ops);
    *ops = mg_ops_add(*ops, mg_ops_scaled(mg_region_setup_ops(), n));
    return ok;
}

/* escape_001: the regions of the reading less the object's echoes and the memory, grown by
 * the margin; the heading nearest the object's bearing every pi/12 within pi/2 of the present
 * one (escape.py's defaults: 16 samples a segment) */
static int board_escape(void *ctx, const mg_task_inputs_t *in, const int32_t obj_mm[2],
                        int32_t detour_mm, int32_t side, int32_t *heading_mrad, mg_ops_t *ops)
{
    enum { PER = MG_GEO_HEAD + MG_REGION_WORDS, N_SIDE = 6 };
    const int64_t step_urad = 261799; /* round(pi / 12 1e6) */
    mg_board_replanner001_t *b = ctx;
    mg_region_t regions[MG_SONAR_MAX_REGIONS + MG_REPLAN_MEMORY];
    int64_t geo[PER * (MG_SONAR_MAX_REGIONS + MG_REPLAN_MEMORY)];
    int64_t clear[MG_CLEAR_WORDS * (MG_SONAR_MAX_REGIONS + MG_REPLAN_MEMORY)];
    const int64_t px = (int64_t)in->x_mm * 16, py = (int64_t)in->y_mm * 16;
    int32_t n = mg_replan001_fresh(&b->cfg, px, py, in->heading_mrad, in->sonar_mm, regions);
    for (int32_t i = 0; i < b->st.n_memory; i++)
        regions[n++] = b->st.memory[i];
    for (int32_t r = 0; r < n; r++) {
        regions[r].r_r_q4 += (int64_t)MG_DETOUR_MARGIN_MM * 16;
        geo[PER * r] = geo[PER * r + 1] = geo[PER * r + 2] = 0;
        mg_region_geo(&regions[r], geo + PER * r + MG_GEO_HEAD);
        mg_region_clear(&regions[r], clear + MG_CLEAR_WORDS * r);
    }
    const int64_t goal_urad = (int64_t)mg_atan2_mrad((int64_t)obj_mm[1] - in->y_mm,
                                                     (int64_t)obj_mm[0] - in->x_mm) * 1000;
    int64_t head_urad = 0;
    const int found = mg_escape_heading_q(geo, clear, n, px, py, (int64_t)in->heading_mrad * 1000,
                                          goal_urad, step_urad, N_SIDE,
                                          ((int64_t)detour_mm + MG_DETOUR_EXTRA_MM) * 16, 16,
                                          side, &head_urad, ops);
    *ops = mg_ops_add(*ops, mg_ops_scaled(mg_region_setup_ops(), n));
    if (found)
        *heading_mrad = (int32_t)mg_div_round64(head_urad, 1000);
    return found;
}

const mg_replanner001_t mg_board_replanner001 = {board_start, board_update, board_start_path,
                                                 board_straight_clear, board_escape};
