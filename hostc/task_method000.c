/* Paper 000's method: radial symbol, Bezier path of eq. (9), dual "+", gripper down
 * (host/task/method000.py). */
#include "task_method000.h"

#include <string.h>

#include "app_factory.h"
#include "json.h"
#include "sonar_guard.h"
#include "task_drive.h"
#include "trig.h"
#include "task_grasp.h"
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
    ms000(t)->board_planner = 0;
}

void mg_method000_set_board_planner(mg_task_t *t, mg_plan000_ctx_t *ctx)
{
    mg_method000_set_planner(t, mg_method000_plan000, ctx);
    ms000(t)->board_planner = 1;
}

/* TaskParams.for_method("000"): the defaults and 000's wander (host/task/method000.py) */
void mg_method000_params(mg_task_params_t *p)
{
    mg_task_params_default(p);
    p->wander_mmps = MG_WANDER_000_MMPS;
    p->search.wander_frames_per_pose = 1;
    p->search.wander_d_theta5_mrad = MG_WANDER_D_THETA5_000_MRAD;
    p->search.outward_from_mm = MG_OUTWARD_FROM_000_MM;
    p->sighting_approach_mm = MG_SIGHTING_APPROACH_000_MM;
    p->search.round_tries = MG_ROUND_TRIES_000;
    p->search.outward_inward_mrad = MG_OUTWARD_INWARD_000_MRAD;
    p->search.edge_mm = MG_EDGE_000_MM;
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

/* a position or time of the planner's counts (1/16 mm, 1/16 ms) in m or s, as Python's repr
 * prints the float count / 16000: the exact decimal count * 625e-7, its trailing zeros cut */
static void json_per_m(mg_json_t *j, int64_t count)
{
    char text[32];
    size_t n = 0;
    const uint64_t v = (count < 0 ? (uint64_t)0 - (uint64_t)count : (uint64_t)count) * 625u;
    if (count < 0)
        text[n++] = '-';
    if (v > 0 && v < 1000u) { /* below 1e-4: 6.25e-05 */
        n = mg_task_text(text, sizeof text, n, "6.25e-05");
        mg_json_raw(j, text, n);
        return;
    }
    n = mg_task_text_int(text, sizeof text, n, (int64_t)(v / 10000000u));
    text[n++] = '.';
    uint64_t frac = v % 10000000u;
    int32_t digits = 7;
    while (digits > 1 && frac % 10u == 0) {
        frac /= 10u;
        digits--;
    }
    for (int32_t k = digits - 1; k >= 0; k--) {
        text[n + (size_t)k] = (char)('0' + (int)(frac % 10u));
        frac /= 10u;
    }
    mg_json_raw(j, text, n + (size_t)digits);
}

void mg_method000_json_ctrl(mg_json_t *j, const int32_t ctrl[12])
{
    mg_json_begin_array(j);
    for (int32_t k = 0; k < 4; k++) {
        mg_json_begin_array(j);
        for (int32_t c = 0; c < 3; c++)
            json_per_m(j, ctrl[3 * k + c]);
        mg_json_end_array(j);
    }
    mg_json_end_array(j);
}

/* the plan's trace detail (method000.py plan_follower): its candidates (every step-th, at
 * most MAX_TRACE_CANDIDATES steps), the feasible ones, the reason, the chosen curve and the
 * plan's modelled ARM9 time */
static char plan_text[MG_TASK_LONG_NOTE_BYTES];
static void note_plan(mg_task_t *t, const mg_plan000_ctx_t *c, const mg_plan_outcome_t *o)
{
    const mg_plan000_t *pl = &c->pl.plan;
    const int32_t n_cand = pl->status == MG_PLAN_STANDOFF ? 0 : pl->n_cand;
    mg_json_t j;
    mg_json_init(&j, plan_text, sizeof plan_text - 1);
    mg_json_begin_object(&j);
    if (o->has_path) {
        mg_json_key(&j, "best_ctrl");
        mg_method000_json_ctrl(&j, pl->best_ctrl);
    }
    mg_json_key(&j, "candidates");
    mg_json_int(&j, n_cand);
    mg_json_key(&j, "candidates_ctrl");
    mg_json_begin_array(&j);
    const int32_t step = n_cand / MG_MAX_TRACE_CANDIDATES > 1 ? n_cand / MG_MAX_TRACE_CANDIDATES
                                                              : 1;
    for (int32_t i = 0; i < n_cand; i += step) {
        int32_t ctrl[12];
        mg_plan000_ctrl(pl, i, ctrl);
        mg_method000_json_ctrl(&j, ctrl);
    }
    mg_json_end_array(&j);
    if (o->has_path) {
        mg_json_key(&j, "duration_us");
        mg_json_int(&j, c->pl.traj.t_us[c->pl.traj.n - 1]);
    }
    mg_json_key(&j, "feasible");
    mg_json_int(&j, pl->status == MG_PLAN_STANDOFF ? 0 : pl->n_feasible);
    mg_json_key(&j, "plan_arm9_us");
    mg_json_int(&j, mg_ops_time_us(&pl->ops));
    mg_json_key(&j, "planner");
    mg_json_string(&j, "000", 3);
    mg_json_key(&j, "reason");
    mg_json_string(&j, o->reason, strlen(o->reason));
    mg_json_end_object(&j);
    if (j.overflow) { /* counted, never silent */
        t->notes_lost++;
        return;
    }
    plan_text[j.len] = 0;
    mg_task_note(t, "plan", plan_text);
}

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
    if (ms->board_planner)
        note_plan(t, (const mg_plan000_ctx_t *)ms->planner_ctx, o);
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
static void path_end(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in, const char *why,
                     const int32_t *error_mm)
{
    (void)in, (void)error_mm;
    mg_task_go(t, now_us, MG_ADJUST, why);
}

const mg_path_method_t mg_path000 = {plan, NULL, sighting_usable, sonar_replan,
                                     hold_before_plan, way_blocked, start_detour, path_wheels,
                                     path_end, 100, 0, NULL};

/* ---- the hooks of the machine's states (the method row) ---- */

static const mg_frame000_t *frame000(const mg_task_inputs_t *in)
{
    return (const mg_frame000_t *)in->frame;
}

void mg_method000_frame_of(const mg_task_t *t, const int32_t *const *words, void *frame)
{
    (void)t;
    mg_frame000_of((mg_frame000_t *)frame, words[MG_DET_RADIAL_SYMBOL], words[MG_DET_DUAL_PLUS],
                   words[MG_DET_SPOKE], words[MG_DET_HELD_FILL], words[MG_DET_RADIAL_CUT]);
}

/* 000's back-off (method000.py back_off_move): the turn toward the symbol, then straight back
 * MG_BACK_OFF_000_MM at slow_mmps; 001's (method001.py back_off_move): the drive away (a
 * detour: turn, then drive, stopping for an echo ahead), then the turn back to face it. 1
 * while it moves; over, the phase is LOOK */
static int back_off_move(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                         mg_cut_back_off_t *bo)
{
    if (bo->phase == MG_BACK_OFF000_TURN) {
        const int32_t turned = mg_task_wrap_mrad((int64_t)in->heading_mrad - bo->a);
        const int32_t want = bo->b < 0 ? -bo->b : bo->b;
        if ((turned < 0 ? -turned : turned) < want) { /* on the spot, left for a positive turn */
            const int32_t dir = bo->b > 0 ? 1 : -1;
            t->wheels[0] = -dir * t->p.turn_wheel_mmps;
            t->wheels[1] = dir * t->p.turn_wheel_mmps;
            return 1;
        }
        bo->phase = MG_BACK_OFF000_BACK;
        bo->a = in->x_mm, bo->b = in->y_mm;
    }
    if (bo->phase == MG_BACK_OFF000_BACK) {
        const int64_t dx = (int64_t)in->x_mm - bo->a;
        const int64_t dy = (int64_t)in->y_mm - bo->b;
        if (dx * dx + dy * dy < (int64_t)MG_BACK_OFF_000_MM * MG_BACK_OFF_000_MM) {
            t->wheels[0] = t->wheels[1] = -t->p.slow_mmps;
            return 1;
        }
        bo->phase = MG_BACK_OFF000_LOOK;
        bo->stopped_us = now_us;
    }
    if (bo->phase == MG_BACK_OFF_AWAY) {
        if (!mg_drive_detour(t, in, &bo->leg))
            return 1;
        memset(&bo->leg, 0, sizeof bo->leg);
        bo->leg.heading_mrad = bo->b;
        bo->phase = MG_BACK_OFF_FACE;
    }
    if (bo->phase == MG_BACK_OFF_FACE) {
        if (!mg_drive_detour(t, in, &bo->leg))
            return 1;
        bo->phase = MG_BACK_OFF000_LOOK;
        bo->stopped_us = now_us;
    }
    return 0;
}

void mg_back_off_away(mg_cut_back_off_t *bo, const mg_task_inputs_t *in, int32_t turn_mrad,
                      int32_t away_mm)
{
    /* face away (turn + pi), drive off, then face it again */
    const int32_t toward = mg_task_wrap_mrad((int64_t)in->heading_mrad + turn_mrad);
    memset(&bo->leg, 0, sizeof bo->leg);
    bo->leg.heading_mrad = mg_task_wrap_mrad((int64_t)toward + 3142);
    bo->leg.drive = 1;
    bo->leg.length_mm = away_mm;
    bo->phase = MG_BACK_OFF_AWAY;
    bo->b = toward;
}

int mg_search_back_off(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                       mg_cut_back_off_t *bo, const mg_back_off_rule_t *rule)
{
    const mg_frame000_t *f = frame000(in);
    if (bo->phase == MG_BACK_OFF000_NONE) {
        if (f == NULL || !f->has_cut)
            return 0;
        /* its bearing (right positive, as the waist's) at the border it is cut at; the base
         * turns left positive */
        int32_t arm[6];
        mg_task_arm_at(t, now_us - t->p.frame_latency_us, arm);
        const int32_t half_fov = mg_atan2_mrad(t->cam.u0_px, t->cam.f_px);
        const int32_t turn = -(arm[5] + f->cut_side * half_fov);
        if (f->cut_low_px >= 2 * t->cam.v0_px
            && MG_CUT_LOOK_FLAT * f->cut_h_px <= f->cut_w_px) { /* near: at the bottom, flat */
            bo->has_cut_seen = 1;
            bo->cut_seen_us = now_us;
            bo->cut_heading_mrad = mg_task_wrap_mrad((int64_t)in->heading_mrad + turn);
        }
        if (bo->back_offs >= rule->max || t->has_confirm_until
            || (rule->from_start
                && (t->lost
                    || (int64_t)in->x_mm * in->x_mm + (int64_t)in->y_mm * in->y_mm
                           > (int64_t)MG_BACK_OFF_FROM_MM * MG_BACK_OFF_FROM_MM)))
            return 0;
        if (rule->wait_us > 0) { /* due at a frame wait_us after the first, within stale_us */
            if (!bo->has_cut_first || now_us - bo->cut_first_us > rule->stale_us) {
                bo->has_cut_first = 1;
                bo->cut_first_us = now_us;
                return 0;
            }
            if (now_us - bo->cut_first_us < rule->wait_us)
                return 0;
            bo->has_cut_first = 0;
        }
        bo->back_offs++;
        if (rule->away_mm > 0) {
            mg_back_off_away(bo, in, turn, rule->away_mm);
        } else {
            bo->phase = MG_BACK_OFF000_TURN;
            bo->a = in->heading_mrad;
            bo->b = turn;
        }
        static const char *const names[3] = {"n", "side", "turn_mrad"};
        const int64_t values[3] = {bo->back_offs, f->cut_side, turn};
        mg_task_note_ints(t, "back_off", 3, names, values);
    }
    if (back_off_move(t, now_us, in, bo))
        return 1;
    /* stand until a frame taken after the stop has come, then a new look-around from here */
    t->wheels[0] = t->wheels[1] = 0;
    if (f == NULL || !f->has_frame || now_us - t->p.frame_latency_us < bo->stopped_us)
        return 1;
    bo->phase = MG_BACK_OFF000_NONE;
    mg_search_init(&t->search, &t->p.search, t->arm[2], t->arm[5], now_us);
    t->has_turn_from = 0;
    t->has_wander_from = 0;
    t->wander_round.active = 0;
    t->has_wander_look = 0;
    return 0;
}

int mg_method000_search_cut_look(const mg_task_t *t, int64_t now_us, int32_t *heading_mrad)
{
    const mg_cut_back_off_t *bo = &((const mg_state000_t *)(const void *)t->ms.bytes)->cut;
    if (!bo->has_cut_seen || now_us - bo->cut_seen_us > MG_CUT_LOOK_000_US)
        return 0;
    *heading_mrad = bo->cut_heading_mrad;
    return 1;
}

int mg_method000_search_back_off(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    static const mg_back_off_rule_t rule = {MG_BACK_OFFS_000, 1, 0, 0, 0};
    return mg_search_back_off(t, now_us, in, &ms000(t)->cut, &rule);
}

int mg_method000_search_sighting(const mg_task_t *t, const mg_task_inputs_t *in, void *sighting)
{
    (void)t;
    const mg_sighting_t *s = mg_method000_radial_result(in);
    if (s == NULL)
        return 0;
    memcpy(sighting, s, sizeof *s);
    return 1;
}

void mg_method000_enter_approach_state(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    (void)now_us, (void)in;
    mg_method000_enter_approach(t);
}

void mg_method000_approach_state(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    mg_method000_approach(t, now_us, in, mg_method000_radial_result(in));
}

const void *mg_method000_plus_result(const mg_task_inputs_t *in)
{
    const mg_frame000_t *f = frame000(in);
    return f != NULL && f->has_plus ? &f->plus : NULL;
}

const mg_sighting_t *mg_method000_radial_result(const mg_task_inputs_t *in)
{
    const mg_frame000_t *f = frame000(in);
    return f != NULL && f->has_radial ? &f->radial : NULL;
}

const void *mg_method000_radial_check(const mg_task_inputs_t *in)
{
    return mg_method000_radial_result(in);
}

void mg_method000_rough_target(mg_task_t *t, const mg_task_inputs_t *in, int32_t target_q4[3])
{
    mg_task_object_target_q4(t, in, t->p.object_top_mm + t->p.hover_mm, 0, target_q4);
    t->has_grasp_xy = 1;
    t->grasp_xy_q4[0] = target_q4[0], t->grasp_xy_q4[1] = target_q4[1];
    if (!t->has_plus_odom)
        return;
    int64_t best = -1;
    for (int32_t k = 0; k < 2; k++) { /* hover over the nearer "+", grasp on the axis */
        int32_t q[2];
        mg_odom_to_platform_q4(in->x_mm, in->y_mm, in->heading_mrad, t->p.mount_forward_mm,
                               t->plus_odom_mm[k][0], t->plus_odom_mm[k][1], q);
        const int64_t d2 = (int64_t)q[0] * q[0] + (int64_t)q[1] * q[1];
        if (best < 0 || d2 < best) {
            best = d2;
            target_q4[0] = q[0], target_q4[1] = q[1];
        }
    }
}

void mg_method000_enter_precise(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    (void)in;
    mg_task_set_arm(t, now_us, t->arm[2], t->arm[3], t->arm[4], t->arm[5], 1,
                    MG_ROLL_PRECISE_MRAD);
    t->phase = MG_PHASE_ROLL;
    t->roll_scan = 0;
}

int mg_method000_spoke_reading(const mg_task_inputs_t *in, int32_t *angle_mrad,
                               int32_t *width_px)
{
    const mg_frame000_t *f = frame000(in);
    if (f == NULL || !f->has_spoke)
        return 0;
    *angle_mrad = f->spoke_angle_mrad;
    *width_px = f->spoke_width_px;
    return 1;
}

/* R > G > B with R at least 1.5 B; the floor (~150, 142, 128) is at most 1.3 */
int mg_method000_body_brown(const int32_t rgb[3])
{
    return rgb[0] >= 40 && rgb[0] > rgb[1] && rgb[1] > rgb[2] && 2 * rgb[0] >= 3 * rgb[2];
}

int mg_method000_held_in_view(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    const mg_frame000_t *f = frame000(in);
    return mg_task_held_fill_in_view(t, now_us, f != NULL && f->has_held_fill,
                                     f != NULL ? f->held_rgb : NULL,
                                     f != NULL ? f->held_permille : 0, mg_method000_body_brown);
}
