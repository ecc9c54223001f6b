/* The grasp states (host/task/grasp.py). */
#include "task_grasp.h"

#include <string.h>

#include "arm_calib.h"
#include "fixedpoint.h"
#include "json.h"
#include "sonar_guard.h"
#include "task_drive.h"
#include "task_method.h"
#include "task_sense.h"
#include "trig.h"

/* the waist turns the view about the place: the estimate that put the fingers beside the
 * object may be off by 0.3 rad in bearing (docs/cosim.md "Measured", T8) */
static const int32_t CHECK_WAIST_MRAD[MG_CHECK_LOOKS] = {0, 300, -300};
/* the common look of the check: the camera this far above the object's top, looking down,
 * the first reachable wins (docs/task.md) */
static const int32_t HELD_VIEW_MM[] = {150, 140, 130, 120, 110, 100, 90};
/* the look before the rough grasp (Method.sight_views): each look (waist offset, wrist roll
 * mrad) held SIGHT_LOOK_US until the dual "+" is seen SIGHT_FRAMES times; a quarter roll lays
 * the line of sight along the frame's width, the waist offsets move the view ~18 mm aside
 * (docs/task.md). Seen outside ADJUST's goal window, the base closes in again, at most
 * MAX_SIGHT_ADJUSTS times a grasp. */
#define SIGHT_FRAMES 3
#define SIGHT_LOOK_US 700000
#define SIGHT_LOOKS 6
#define MAX_SIGHT_ADJUSTS 2
/* the retry after a blind miss with no evidence, the object not seen since (docs/task.md) */
#define REGRASP_UNSEEN "grasp missed at the estimate, object not seen since: searching before " \
                       "grasping again"
static const int32_t SIGHT_LOOKS_MRAD[SIGHT_LOOKS][2] = {{0, 0},    {0, 1571},  {150, 1571},
                                                         {150, 0},  {-150, 0},  {-150, 1571}};

static void note_ints(mg_task_t *t, const char *key, const int32_t *v, int32_t n)
{
    char text[MG_TASK_NOTE_BYTES];
    mg_json_t j;
    mg_json_init(&j, text, sizeof text - 1);
    mg_json_begin_array(&j);
    for (int32_t i = 0; i < n; i++)
        mg_json_int(&j, v[i]);
    mg_json_end_array(&j);
    mg_json_terminate(&j);
    mg_task_note(t, key, text);
}

void mg_task_note_pose(mg_task_t *t, const char *key, const mg_arm_pose_t *p)
{
    const int32_t v[4] = {p->theta2_mrad, p->theta3_mrad, p->theta4_mrad, p->theta5_mrad};
    note_ints(t, key, v, 4);
}

static void note_text(mg_task_t *t, const char *key, const char *s)
{
    char text[MG_TASK_NOTE_BYTES];
    mg_json_t j;
    mg_json_init(&j, text, sizeof text - 1);
    mg_json_string(&j, s, strlen(s));
    mg_json_terminate(&j);
    mg_task_note(t, key, text);
}

static int32_t obj_dist_mm(const mg_task_t *t, const mg_task_inputs_t *in, int32_t xy[2])
{
    mg_task_obj_platform(t, in, xy);
    return (int32_t)(mg_isqrt((int64_t)xy[0] * xy[0] + (int64_t)xy[1] * xy[1]) >> 4);
}

void mg_task_object_target_q4(const mg_task_t *t, const mg_task_inputs_t *in, int32_t height_mm,
                              int32_t back_mm, int32_t out_q4[3])
{
    int32_t xy[2];
    mg_task_obj_platform(t, in, xy);
    int64_t x = xy[0], y = xy[1];
    if (back_mm) {
        const int64_t rho = mg_isqrt(x * x + y * y), back = (int64_t)back_mm * 16;
        if (rho > back) {
            x = mg_floor_div(x * (rho - back), rho);
            y = mg_floor_div(y * (rho - back), rho);
        }
    }
    out_q4[0] = (int32_t)x;
    out_q4[1] = (int32_t)y;
    out_q4[2] = (height_mm - t->p.h_shoulder_mm) * 16;
}

/* "<lead>: <the IK's reason>" */
static void fail_ik(mg_task_t *t, int64_t now_us, const char *lead, int32_t code, int64_t detail,
                    const mg_arm_pose_t *pose)
{
    char why[MG_TASK_WHY];
    const size_t n = mg_task_text(why, sizeof why, 0, lead);
    mg_task_ik_reason(&t->geom, code, detail, pose, why, sizeof why, n);
    mg_task_fail(t, now_us, why);
}

/* the gripper above the object by hover_mm (Method.rough_target) */
static void rough_pose(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    const struct mg_task_method *r = t->rules;
    t->phase = MG_PHASE_NONE;
    int32_t target[3];
    r->rough_target(t, in, target);
    mg_arm_pose_t pose;
    int64_t detail;
    int32_t code = r->grasp_ik(&t->geom, target, &pose, &detail);
    if (code != MG_IK_OK && r->lowers_hover) {
        /* a few mm beyond reach: hover lower, in 10 mm steps down to half the hover height */
        for (int32_t drop = 10; drop <= t->p.hover_mm / 2; drop += 10) {
            const int32_t lower[3] = {target[0], target[1], target[2] - drop * 16};
            mg_arm_pose_t p2;
            int64_t d2;
            const int32_t c2 = r->grasp_ik(&t->geom, lower, &p2, &d2);
            if (c2 == MG_IK_OK) {
                memcpy(target, lower, sizeof target);
                code = c2, pose = p2;
                break;
            }
            code = c2, pose = p2, detail = d2;
        }
    }
    const int32_t mm[3] = {(int32_t)mg_floor_div(target[0], 16),
                           (int32_t)mg_floor_div(target[1], 16),
                           (int32_t)mg_floor_div(target[2], 16)};
    note_ints(t, "rough_target_mm", mm, 3);
    if (code != MG_IK_OK && t->sight_adjusts < MAX_SIGHT_ADJUSTS) {
        /* the object beside or behind the arm's reach (001 arrived on its grasp circle facing
         * past it, docs/task.md): the base closes in on it first, as after a look that saw it
         * outside ADJUST's goal */
        t->sight_adjusts++;
        char why[MG_TASK_WHY];
        size_t n = mg_task_text(why, sizeof why, 0, "rough grasp out of reach (");
        n = mg_task_ik_reason(&t->geom, code, detail, &pose, why, sizeof why, n);
        mg_task_text(why, sizeof why, n, "): closer in first");
        mg_task_go(t, now_us, MG_ADJUST, why);
        return;
    }
    if (code != MG_IK_OK) {
        fail_ik(t, now_us, "rough grasp IK: ", code, detail, &pose);
        return;
    }
    t->grasp_alpha_mrad = pose.theta2_mrad + pose.theta3_mrad + pose.theta4_mrad;
    mg_task_apply_pose(t, now_us, &pose, 1, 0);
    mg_task_note_pose(t, "rough_pose_mrad", &pose);
}

/* A camera pose looking down at the object's top from the method's views (range mm, pitch
 * down mrad): back along the place's bearing and up, by eq. (11) of 000 with alpha_T = -pitch;
 * the first the arm reaches: 1, or 0 when none is (grasp.py _view_pose). */
static int view_pose(const mg_task_t *t, const mg_task_inputs_t *in, mg_arm_pose_t *pose)
{
    const struct mg_task_method *r = t->rules;
    if (!t->has_obj)
        return 0;
    int32_t xy[2];
    mg_task_obj_platform(t, in, xy);
    const int64_t rho = mg_isqrt((int64_t)xy[0] * xy[0] + (int64_t)xy[1] * xy[1]);
    const int32_t look_mm = r->look_height_mm(&t->p, 1);
    for (int32_t i = 0; i < r->n_sight_views && i < MG_MAX_SIGHT_VIEWS; i++) {
        const int64_t d_q4 = (int64_t)r->sight_views[i][0] * 16;
        const int32_t pitch = r->sight_views[i][1];
        const int64_t back = mg_floor_div(d_q4 * mg_cos_q12(pitch), 4096), rr = rho - back;
        if (rr < 20 * 16)
            continue;
        const int32_t target[3] = {
            (int32_t)mg_floor_div(xy[0] * rr, rho), (int32_t)mg_floor_div(xy[1] * rr, rho),
            (int32_t)((int64_t)(look_mm - t->p.h_shoulder_mm) * 16
                      + mg_floor_div(d_q4 * mg_sin_q12(pitch), 4096))};
        int64_t detail;
        if (mg_ik_pitch_mm_q4(&t->geom, target, -pitch, pose, &detail) == MG_IK_OK)
            return 1;
    }
    return 0;
}

void mg_task_enter_rough_grasp(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    const struct mg_task_method *r = t->rules;
    t->wheels[0] = t->wheels[1] = 0;
    t->gripper = 0;
    if (!t->graspable_seen && r->object_cue_seen && r->object_cue_seen(t)) {
        /* ADJUST finished on an estimate the object's detector never confirmed, though a cue
         * of the object was seen (docs/task.md): search again, the estimate dropped (it was
         * looked at and the object is not there; kept, it decided the next approach) */
        t->has_obj = 0;
        t->lost_in = MG_ROUGH_GRASP;
        mg_task_go(t, now_us, MG_LOST, "object never sighted at its estimated place, its cue "
                                       "seen before: searching before any grasp");
        return;
    }
    if (!t->graspable_seen) {
        /* the estimate came from a guide (002's board) alone: nothing seen to grasp */
        char why[MG_TASK_WHY];
        size_t n = mg_task_text(why, sizeof why, 0, "no graspable object found (");
        n = mg_task_text(why, sizeof why, n, r->object_detectors);
        mg_task_text(why, sizeof why, n, " never seen)");
        mg_task_fail(t, now_us, why);
        return;
    }
    if (t->regrasps && !t->object_sighted && !r->n_sight_views) {
        /* a grasp at this estimate found no evidence and the camera has not seen the object
         * since (docs/task.md): the same blind grasp again would miss again */
        t->lost_in = MG_ROUGH_GRASP;
        mg_task_go(t, now_us, MG_LOST, REGRASP_UNSEEN);
        return;
    }
    t->has_reach = r->grasp_reach_mm && r->grasp_reach_mm(t, &t->reach_mm[0], &t->reach_mm[1]);
    if (t->has_reach) {
        int32_t xy[2];
        const int32_t dist = obj_dist_mm(t, in, xy), off = dist - t->reach_mm[0];
        if ((off < 0 ? -off : off) > t->reach_mm[1]) {
            /* the grasp pose needs the object elsewhere (002's level grasp): drive there */
            static const char *const names[3] = {"dist_mm", "goal_mm", "tol_mm"};
            const int64_t values[3] = {dist, t->reach_mm[0], t->reach_mm[1]};
            mg_task_note_ints(t, "grasp_reach", 3, names, values);
            t->phase = MG_PHASE_REACH;
            return;
        }
    }
    mg_arm_pose_t pose;
    if (!r->n_sight_views || !view_pose(t, in, &pose)) {
        rough_pose(t, now_us, in);
        return;
    }
    /* the look before the grasp (Method.sight_views): the base stands still from here on */
    mg_task_apply_pose(t, now_us, &pose, 1, SIGHT_LOOKS_MRAD[0][1]);
    t->trust_from_us = t->move_done_us; /* frames of the swing: arm pose unknown */
    t->sight_frames = t->sight_look = 0;
    t->sight_th5_mrad = pose.theta5_mrad;
    t->phase = MG_PHASE_SIGHT, t->phase_us = t->move_done_us;
    mg_task_note_pose(t, "sight_pose_mrad", &pose);
}

/* The look before the grasp: sightings of the dual "+" with the base standing still give the
 * estimate the grasp goes on. Each look is held for SIGHT_LOOK_US until the pair is seen
 * (SIGHT_FRAMES frames, or fewer by the end of that look). Then the method decides (001 from
 * its grasp circle); else not seen at any look, an object the camera never saw is searched for
 * (LOST); seen outside ADJUST's goal window, the base closes in again first; else the rough
 * grasp on the estimate (grasp.py _sight). */
static void sight(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    const struct mg_task_method *r = t->rules;
    const void *det = r->sight_result ? r->sight_result(in) : NULL;
    if (det && mg_task_settled(t, now_us)
        && mg_task_see_object(t, now_us, in, r->sight_position, det, 1))
        t->sight_frames++;
    if (t->sight_frames < SIGHT_FRAMES && now_us - t->phase_us < SIGHT_LOOK_US)
        return;
    const int32_t k = t->sight_look;
    if (!t->sight_frames && k + 1 < SIGHT_LOOKS) { /* not seen: the next look */
        t->sight_look = k + 1;
        mg_task_set_arm(t, now_us, t->arm[2], t->arm[3], t->arm[4],
                        t->sight_th5_mrad + SIGHT_LOOKS_MRAD[k + 1][0], 1,
                        SIGHT_LOOKS_MRAD[k + 1][1]);
        t->trust_from_us = t->move_done_us;
        t->phase_us = t->move_done_us;
        return;
    }
    int32_t xy[2], goal_mm, tol_mm;
    const int32_t dist = obj_dist_mm(t, in, xy);
    r->adjust_goal_mm(t, &goal_mm, &tol_mm);
    {
        char text[MG_TASK_NOTE_BYTES];
        mg_json_t j;
        mg_json_init(&j, text, sizeof text - 1);
        mg_json_begin_object(&j);
        mg_json_key(&j, "bearing_mrad");
        mg_json_int(&j, mg_atan2_mrad(xy[0], xy[1]));
        mg_json_key(&j, "dist_mm");
        mg_json_int(&j, dist);
        mg_json_key(&j, "frames");
        mg_json_int(&j, t->sight_frames);
        mg_json_key(&j, "look_mrad");
        mg_json_int_pair(&j, SIGHT_LOOKS_MRAD[k][0], SIGHT_LOOKS_MRAD[k][1]);
        mg_json_end_object(&j);
        mg_json_terminate(&j);
        mg_task_note(t, "sight", text);
    }
    if (r->look_decides && r->look_decides(t, now_us, in))
        return; /* the method's grasp on this look (001 from its grasp circle) */
    if (!t->sight_frames && !t->object_sighted) {
        t->lost_in = MG_ROUGH_GRASP;
        mg_task_go(t, now_us, MG_LOST, t->regrasps ? REGRASP_UNSEEN
                                                   : "object not seen at its estimated place, "
                                                     "never seen by the camera: searching "
                                                     "before any grasp");
        return;
    }
    const int32_t off = dist - goal_mm;
    if (t->sight_frames && (off < 0 ? -off : off) > tol_mm
        && t->sight_adjusts < MAX_SIGHT_ADJUSTS) {
        t->sight_adjusts++;
        char why[MG_TASK_WHY];
        size_t n = mg_task_text(why, sizeof why, 0, "object sighted ");
        n = mg_task_text_int(why, sizeof why, n, dist);
        n = mg_task_text(why, sizeof why, n, " mm ahead of the waist, outside ");
        n = mg_task_text_int(why, sizeof why, n, goal_mm);
        n = mg_task_text(why, sizeof why, n, " +- ");
        n = mg_task_text_int(why, sizeof why, n, tol_mm);
        mg_task_text(why, sizeof why, n, " mm: closer in first");
        mg_task_go(t, now_us, MG_ADJUST, why);
        return;
    }
    rough_pose(t, now_us, in);
}

void mg_task_do_rough_grasp(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    t->wheels[0] = t->wheels[1] = 0;
    if (t->phase == MG_PHASE_REACH) {
        int32_t xy[2], wheels[2];
        mg_task_obj_platform(t, in, xy);
        mg_close_in_t d;
        const int done = mg_close_in(xy, t->reach_mm[0], t->reach_mm[1], t->p.bearing_tol_mrad,
                                     t->rules->adjust_vmax_mmps(&t->p), wheels, &d);
        int32_t phi, rng; /* something in front of the object: grasp from here */
        const int echo = (int64_t)wheels[0] + wheels[1] > 0 ? mg_close_echo(t, in, &phi, &rng)
                                                           : 0;
        if (echo)
            mg_note_close_echo(t, echo == 2, phi, rng);
        if (done || echo)
            rough_pose(t, now_us, in);
        else
            t->wheels[0] = wheels[0], t->wheels[1] = wheels[1];
    } else if (t->phase == MG_PHASE_SIGHT) {
        sight(t, now_us, in);
    } else if (mg_task_settled(t, now_us)) {
        mg_task_go(t, now_us, MG_PRECISE_GRASP, "arm at the rough grasp pose");
    }
}

void mg_task_enter_precise_grasp(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    t->sight_adjusts = 0; /* the next grasp's look may send the base closer again */
    t->precise_steps = 0;
    t->has_close_by = 0;
    t->phase_us = now_us;
    t->rules->enter_precise(t, now_us, in);
}

int mg_task_move_point(mg_task_t *t, int64_t now_us, const int32_t xyz_q4[3], int32_t has_th1,
                       int32_t th1)
{
    mg_arm_pose_t pose;
    int64_t detail;
    const int32_t code = mg_ik_pitch_mm_q4(&t->geom, xyz_q4, t->grasp_alpha_mrad, &pose, &detail);
    if (code != MG_IK_OK) {
        char why[MG_TASK_WHY];
        mg_task_ik_reason(&t->geom, code, detail, &pose, why, sizeof why, 0);
        note_text(t, "precise_unreachable", why);
        return 0;
    }
    mg_task_apply_pose(t, now_us, &pose, has_th1, th1);
    return 1;
}

void mg_task_descend(mg_task_t *t, int64_t now_us, const char *why, const char *condition)
{
    int32_t p[3];
    mg_task_gripper_point_q4(t, p);
    if (t->has_grasp_xy && t->p.precise_align_ch == 1)
        p[0] = t->grasp_xy_q4[0], p[1] = t->grasp_xy_q4[1];
    p[2] = (t->p.grasp_height_mm - t->p.h_shoulder_mm) * 16;
    if (!mg_task_move_point(t, now_us, p, 0, 0)) {
        mg_task_fail(t, now_us, "precise grasp: grasp height unreachable");
        return;
    }
    t->phase = MG_PHASE_LOWER;
    t->has_close_by = 1;
    mg_task_text(t->close_by, sizeof t->close_by, 0, condition);
    note_text(t, "precise_descend", why);
}

/* the reason of a precise step (kinematics.py precise_grasp_step) */
static size_t precise_reason(const mg_task_t *t, const mg_precise_step_t *st, int32_t w_px,
                             char *out, size_t cap)
{
    size_t n = 0;
    if (st->slope_ok) {
        n = mg_task_text(out, cap, n, "k_T ~ 0");
    } else {
        n = mg_task_text(out, cap, n, "spoke at ");
        n = mg_task_text_int(out, cap, n, st->angle_mrad);
        n = mg_task_text(out, cap, n, " mrad: turn");
    }
    n = mg_task_text(out, cap, n, "; w_T ");
    n = mg_task_text_int(out, cap, n, w_px);
    if (w_px < t->p.w_min_px) {
        n = mg_task_text(out, cap, n, " px < ");
        n = mg_task_text_int(out, cap, n, t->p.w_min_px);
        return mg_task_text(out, cap, n, ": lower");
    }
    if (w_px > t->p.w_max_px) {
        n = mg_task_text(out, cap, n, " px > ");
        n = mg_task_text_int(out, cap, n, t->p.w_max_px);
        return mg_task_text(out, cap, n, ": raise");
    }
    return mg_task_text(out, cap, n, " px in range");
}

/* 000 section III.C.2: on each spoke reading turn until k_T = 0 and move up or down until
 * w_T is in [w_min, w_max]; no spoke: roll the camera by ROLL_SCAN_MRAD at a time, then the
 * method's search or the rough position */
static void align(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    if (!mg_task_settled(t, now_us))
        return; /* the frame may predate the last move */
    int32_t spoke_mrad = 0, w_px = 0, p[3];
    const int seen = t->rules->spoke_reading && t->rules->spoke_reading(in, &spoke_mrad, &w_px);
    if (!seen) {
        const int64_t waited = now_us - t->phase_us;
        if (t->roll_scan < MG_ROLL_SCAN_STEPS && waited >= t->p.spoke_wait_us / 3) {
            /* the spoke detector sees arms within 30 degrees of the image x axis: roll the
             * camera by 30 degrees at a time over the quarter turn the "+" repeats in */
            t->roll_scan++;
            mg_task_gripper_point_q4(t, p);
            mg_task_move_point(t, now_us, p, 1, t->arm[1] - MG_ROLL_SCAN_MRAD);
            t->phase_us = now_us;
        } else if (waited >= t->p.spoke_wait_us
                   && !(t->rules->grasp_lost && t->rules->grasp_lost(t, now_us, waited))) {
            char why[MG_TASK_WHY];
            size_t n = mg_task_text(why, sizeof why, 0, "no spoke seen for ");
            n = mg_task_text_int(why, sizeof why, n, waited);
            mg_task_text(why, sizeof why, n, " us: rough position");
            mg_task_descend(t, now_us, why, "no_spoke");
        }
        return;
    }
    t->phase_us = now_us;
    t->precise_steps++;
    const mg_precise_params_t pp = {35, 150, 1, 10, t->p.w_min_px, t->p.w_max_px};
    mg_precise_step_t st;
    mg_precise_grasp_step(t->arm[5], spoke_mrad, w_px, &pp, &st);
    char reason[MG_TASK_WHY];
    precise_reason(t, &st, w_px, reason, sizeof reason);
    {
        char text[MG_TASK_NOTE_BYTES];
        mg_json_t j;
        mg_json_init(&j, text, sizeof text - 1);
        mg_json_begin_object(&j);
        mg_json_key(&j, "reason");
        mg_json_string(&j, reason, strlen(reason));
        mg_json_key(&j, "spoke_mrad");
        mg_json_int(&j, spoke_mrad);
        mg_json_key(&j, "step");
        mg_json_int(&j, t->precise_steps);
        mg_json_key(&j, "w_px");
        mg_json_int(&j, w_px);
        mg_json_end_object(&j);
        mg_json_terminate(&j);
        mg_task_note(t, "precise", text);
    }
    char why[MG_TASK_WHY];
    if (st.aligned) {
        size_t n = mg_task_text(why, sizeof why, 0, "k_T ~ 0 and w_T = ");
        n = mg_task_text_int(why, sizeof why, n, w_px);
        mg_task_text(why, sizeof why, n, " px");
        mg_task_descend(t, now_us, why, "precise");
        return;
    }
    if (t->precise_steps >= t->p.precise_max_steps) {
        size_t n = mg_task_text(why, sizeof why, 0, "not aligned after ");
        n = mg_task_text_int(why, sizeof why, n, t->precise_steps);
        n = mg_task_text(why, sizeof why, n, " steps: ");
        mg_task_text(why, sizeof why, n, reason);
        mg_task_descend(t, now_us, why, "max_steps");
        return;
    }
    mg_task_gripper_point_q4(t, p);
    p[2] += st.dz_mm * 16;
    if (t->p.precise_align_ch == 1) {
        /* roll about the vertical l3: the gripper stays above the object; the spokes repeat
         * every quarter turn, so stay inside the roll limits by taking the neighbour spoke */
        int32_t roll = t->arm[1] + st.d_align_mrad;
        roll += roll > mg_joint_hi_mrad(1)   ? -MG_QUARTER_TURN_MRAD
                : roll < mg_joint_lo_mrad(1) ? MG_QUARTER_TURN_MRAD
                                             : 0;
        mg_task_move_point(t, now_us, p, 1, roll);
        return;
    }
    const int64_t rho = mg_isqrt((int64_t)p[0] * p[0] + (int64_t)p[1] * p[1]);
    p[0] = (int32_t)((rho * mg_sin_q12(st.theta5_mrad) + 2048) >> 12);
    p[1] = (int32_t)((rho * mg_cos_q12(st.theta5_mrad) + 2048) >> 12);
    mg_task_move_point(t, now_us, p, 1, st.theta1_mrad);
}

void mg_task_do_precise_grasp(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    t->wheels[0] = t->wheels[1] = 0;
    switch (t->phase) {
    case MG_PHASE_ROLL:
        if (mg_task_settled(t, now_us))
            t->phase = MG_PHASE_ALIGN, t->phase_us = now_us;
        return;
    case MG_PHASE_ALIGN:
        align(t, now_us, in);
        return;
    case MG_PHASE_LOWER:
        if (mg_task_settled(t, now_us)) {
            t->gripper = 1000;
            t->phase = MG_PHASE_CLOSE, t->phase_us = now_us;
            /* what closed the gripper; "pose_reached": the move-in of 002, no alignment */
            note_text(t, "grasp_close", t->has_close_by ? t->close_by : "pose_reached");
        }
        return;
    case MG_PHASE_CLOSE:
        if (in->grasp_closed)
            mg_task_go(t, now_us, MG_LIFT, "gripper closed on the object");
        else if (now_us - t->phase_us >= t->p.grasp_close_timeout_us)
            mg_task_fail(t, now_us, "gripper closed but no object held");
        return;
    default:
        return;
    }
}

void mg_task_enter_lift(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    (void)in;
    t->phase = MG_PHASE_RAISE, t->check_seen = 0;
    int32_t p[3];
    mg_task_gripper_point_q4(t, p);
    p[2] += t->p.lift_mm * 16;
    if (!mg_task_move_point(t, now_us, p, 0, 0)) /* out of reach straight up: the shoulder */
        mg_task_set_arm(t, now_us, t->arm[2], t->arm[3], t->arm[4] + 300, t->arm[5], 0, 0);
}

/* the common look of the check: the camera straight above the fingertip, looking down,
 * HELD_VIEW_MM above the object's top, the first height the arm reaches */
static int held_pose(const mg_task_t *t, mg_arm_pose_t *pose)
{
    int32_t p[3];
    mg_task_gripper_point_q4(t, p);
    for (size_t i = 0; i < sizeof HELD_VIEW_MM / sizeof HELD_VIEW_MM[0]; i++) {
        p[2] = (t->p.object_top_mm + HELD_VIEW_MM[i] - t->p.h_shoulder_mm) * 16;
        int64_t detail;
        if (mg_ik_pitch_mm_q4(&t->geom, p, MG_ALPHA_DOWN_MRAD, pose, &detail) == MG_IK_OK)
            return 1;
    }
    return 0;
}

/* raise the camera above the gripper looking down; the waist then turns through the offsets */
static void start_check(mg_task_t *t, int64_t now_us)
{
    mg_arm_pose_t pose;
    const int has = (t->rules->held_view_pose && t->rules->held_view_pose(t, &pose))
                    || held_pose(t, &pose);
    if (has) {
        mg_task_apply_pose(t, now_us, &pose, 0, 0);
        mg_task_note_pose(t, "grasp_check_pose_mrad", &pose);
    } else {
        mg_task_note(t, "grasp_check_no_view", "true"); /* no evidence can come: a miss */
    }
    t->trust_from_us = t->move_done_us; /* frames of the swing: arm pose unknown */
    t->check_centre_mrad = t->arm[5], t->check_k = 0;
    memset(t->held, 0, sizeof t->held);
    t->phase = MG_PHASE_CHECK, t->phase_us = t->move_done_us;
}

static void tip_odom(const mg_task_t *t, const mg_task_inputs_t *in, int32_t out[2])
{
    int32_t p[3];
    mg_task_gripper_point_q4(t, p);
    mg_platform_to_odom_mm(in->x_mm, in->y_mm, in->heading_mrad, t->p.mount_forward_mm, p, out);
}

/* no grasp: open and ADJUST again, up to MG_MAX_REGRASPS times, then FAILED */
static void missed(mg_task_t *t, int64_t now_us, const char *why)
{
    char text[MG_TASK_WHY];
    size_t n = mg_task_text(text, sizeof text, 0, "grasp check: ");
    n = mg_task_text(text, sizeof text, n, why);
    t->regrasps++;
    if (t->regrasps > MG_MAX_REGRASPS) {
        n = mg_task_text(text, sizeof text, n, ", after ");
        n = mg_task_text_int(text, sizeof text, n, t->regrasps);
        mg_task_text(text, sizeof text, n, " grasps");
        mg_task_fail(t, now_us, text);
        return;
    }
    t->gripper = 0;
    mg_task_text(text, sizeof text, n, ": open and grasp again");
    mg_task_go(t, now_us, MG_ADJUST, text);
}

/* this frame during the look: the held object filling it (kept per waist offset), or the
 * object seen standing away from the gripper; 1 once the sightings away make a miss */
static int seen_standing(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    const struct mg_task_method *r = t->rules;
    const int32_t had = t->has_obj, place[2] = {t->obj_mm[0], t->obj_mm[1]};
    if (t->phase == MG_PHASE_CHECK && mg_task_settled(t, now_us) && r->held_in_view
        && r->held_in_view(t, now_us, in)) {
        t->held[t->check_k] = 1;
        tip_odom(t, in, t->held_tip_mm[t->check_k]);
    }
    for (int32_t c = 0; c < r->n_checks && c < MG_MAX_CHECKS; c++) {
        const void *det = r->checks[c].result(in);
        if (!det || !had || !mg_task_see_object(t, now_us, in, r->checks[c].position, det,
                                                r->checks[c].is_object))
            continue;
        int32_t tip[2];
        tip_odom(t, in, tip);
        const int64_t dx = (int64_t)t->obj_mm[0] - tip[0], dy = (int64_t)t->obj_mm[1] - tip[1];
        if (dx * dx + dy * dy > (int64_t)MG_CHECK_AWAY_MM * MG_CHECK_AWAY_MM) {
            t->check_seen++;
            char text[MG_TASK_NOTE_BYTES];
            mg_json_t j;
            mg_json_init(&j, text, sizeof text - 1);
            mg_json_begin_object(&j);
            mg_json_key(&j, "estimate_mm");
            mg_json_int_pair(&j, place[0], place[1]);
            mg_json_key(&j, "name");
            mg_json_string(&j, r->checks[c].detector, strlen(r->checks[c].detector));
            mg_json_key(&j, "obj_mm");
            mg_json_int_pair(&j, t->obj_mm[0], t->obj_mm[1]);
            mg_json_end_object(&j);
            mg_json_terminate(&j);
            mg_task_note(t, "grasp_check_seen", text);
            break;
        }
        t->obj_mm[0] = place[0], t->obj_mm[1] = place[1]; /* seen near the fingertip's place:
                                                           * keep the estimate */
    }
    if (t->check_seen < MG_CHECK_SEEN_FRAMES)
        return 0;
    char why[MG_TASK_WHY];
    size_t n = mg_task_text(why, sizeof why, 0,
                            "object still standing away from the gripper (seen in ");
    n = mg_task_text_int(why, sizeof why, n, t->check_seen);
    mg_task_text(why, sizeof why, n, " frames)");
    missed(t, now_us, why);
    return 1;
}

int mg_task_held_evidence(const mg_task_t *t)
{
    for (int32_t a = 0; a < MG_CHECK_LOOKS; a++)
        for (int32_t b = a + 1; b < MG_CHECK_LOOKS; b++) {
            if (!t->held[a] || !t->held[b])
                continue;
            const int64_t dx = (int64_t)t->held_tip_mm[a][0] - t->held_tip_mm[b][0];
            const int64_t dy = (int64_t)t->held_tip_mm[a][1] - t->held_tip_mm[b][1];
            if (dx * dx + dy * dy >= (int64_t)MG_HELD_MOVE_MM * MG_HELD_MOVE_MM)
                return 1;
        }
    return 0;
}

/* the close was decided on the camera's view of the object where the fingers went
 * (grasp.py CLOSES_ON_SIGHT): the spoke aligned or seen until the steps ran out, 001's look
 * confirming it; the others are blind */
static int close_on_sight(const mg_task_t *t)
{
    return t->has_close_by && (strcmp(t->close_by, "precise") == 0
                               || strcmp(t->close_by, "max_steps") == 0
                               || strcmp(t->close_by, "ik") == 0);
}

/* the look of the grasp check: each waist offset for MG_CHECK_POSE_US; DONE on positive
 * evidence, else a miss */
static void check(mg_task_t *t, int64_t now_us)
{
    if (mg_task_held_evidence(t)) {
        /* the offsets held under, sorted: 300 and -300 are the 2nd and 3rd looks */
        static const int32_t ORDER[MG_CHECK_LOOKS] = {2, 0, 1};
        char why[MG_TASK_WHY];
        size_t n = mg_task_text(why, sizeof why, 0, "object held: it fills the hand camera's "
                                                    "frame at waist offsets [");
        int first = 1;
        for (int32_t i = 0; i < MG_CHECK_LOOKS; i++) {
            if (!t->held[ORDER[i]])
                continue;
            n = mg_task_text(why, sizeof why, n, first ? "" : ", ");
            n = mg_task_text_int(why, sizeof why, n, CHECK_WAIST_MRAD[ORDER[i]]);
            first = 0;
        }
        mg_task_text(why, sizeof why, n, "] mrad (grasp check)");
        mg_task_go(t, now_us, MG_DONE, why);
        return;
    }
    if (!mg_task_settled(t, now_us) || now_us - t->phase_us < MG_CHECK_POSE_US)
        return;
    if (t->check_k + 1 < MG_CHECK_LOOKS) { /* the next waist offset: the gripper moves */
        t->check_k++;
        mg_task_set_arm(t, now_us, t->arm[2], t->arm[3], t->arm[4],
                        t->check_centre_mrad + CHECK_WAIST_MRAD[t->check_k], 0, 0);
        t->trust_from_us = t->move_done_us;
        t->phase_us = t->move_done_us;
        return;
    }
    if (!t->check_seen && !close_on_sight(t))
        t->object_sighted = 0; /* a blind grasp where the camera does not see the object: its
                                * sighting before counts no more, the next grasp goes on a new
                                * one (docs/task.md) */
    missed(t, now_us, "no evidence of the object in the gripper");
}

void mg_task_do_lift(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    t->wheels[0] = t->wheels[1] = 0;
    if (!in->grasp_closed) {
        mg_task_fail(t, now_us, "object dropped during the lift");
        return;
    }
    if (seen_standing(t, now_us, in))
        return;
    if (t->phase == MG_PHASE_RAISE) {
        if (mg_task_settled(t, now_us))
            start_check(t, now_us);
        return;
    }
    check(t, now_us);
}

int mg_task_held_fill_in_view(mg_task_t *t, int64_t now_us, int32_t has_fill,
                              const int32_t rgb[3], int32_t fill_permille,
                              int (*colour)(const int32_t rgb[3]))
{
    if (!has_fill || now_us - t->p.frame_latency_us < t->trust_from_us)
        return 0;
    const int held = colour(rgb);
    char text[MG_TASK_NOTE_BYTES];
    mg_json_t j;
    mg_json_init(&j, text, sizeof text - 1);
    mg_json_begin_object(&j);
    mg_json_key(&j, "held");
    mg_json_bool(&j, held);
    mg_json_key(&j, "permille");
    mg_json_int(&j, fill_permille);
    mg_json_key(&j, "rgb");
    mg_json_begin_array(&j);
    for (int i = 0; i < 3; i++)
        mg_json_int(&j, rgb[i]);
    mg_json_end_array(&j);
    mg_json_end_object(&j);
    mg_json_terminate(&j);
    mg_task_note(t, "grasp_check_fill", text);
    return held;
}
