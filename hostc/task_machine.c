/* The task state machine (host/task/machine.py): transitions, timeouts and the bookkeeping the
 * states share. */
#include "task_machine.h"

#include <string.h>

#include "arm_calib.h"
#include "fixedpoint.h"
#include "json.h"
#include "posture.h"
#include "task_adjust.h"
#include "task_grasp.h"
#include "task_search.h"
#include "task_sense.h"
#include "task_method.h"

static const char *const STATE_NAMES[MG_N_TASK_STATES] = {
    "SEARCH", "APPROACH", "ADJUST", "ROUGH_GRASP", "PRECISE_GRASP", "LIFT", "DONE", "LOST",
    "FAILED"};
/* gripper open, roll 0, camera looking down */
static const int32_t HOME_ARM[6] = {0, 0, -1571, -1571, 1571, 0};

const char *mg_task_state_name(int32_t state)
{
    return state >= 0 && state < MG_N_TASK_STATES ? STATE_NAMES[state] : "?";
}

int mg_task_terminal(int32_t state)
{
    return state == MG_DONE || state == MG_FAILED;
}

size_t mg_task_text(char *out, size_t cap, size_t at, const char *s)
{
    while (*s && at + 1 < cap)
        out[at++] = *s++;
    if (at < cap)
        out[at] = 0;
    return at;
}

size_t mg_task_text_int(char *out, size_t cap, size_t at, int64_t v)
{
    char digits[24];
    int n = 0;
    uint64_t m = v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v;
    do {
        digits[n++] = (char)('0' + (int)(m % 10u));
        m /= 10u;
    } while (m);
    if (v < 0)
        digits[n++] = '-';
    char text[24];
    for (int i = 0; i < n; i++)
        text[i] = digits[n - 1 - i];
    text[n] = 0;
    return mg_task_text(out, cap, at, text);
}

size_t mg_task_text_q4_1(char *out, size_t cap, size_t at, int64_t v_q4)
{
    /* sixteenths are exact binary fractions: a tie rounds to even, as the float's repr does */
    const int neg = v_q4 < 0;
    const uint64_t m = neg ? (uint64_t)0 - (uint64_t)v_q4 : (uint64_t)v_q4;
    uint64_t tenths = m * 10u / 16u;
    const uint64_t rem = m * 10u % 16u;
    if (rem > 8u || (rem == 8u && (tenths & 1u)))
        tenths++;
    if (neg) /* -0.0 too, as Python prints it */
        at = mg_task_text(out, cap, at, "-");
    at = mg_task_text_int(out, cap, at, (int64_t)(tenths / 10u));
    at = mg_task_text(out, cap, at, ".");
    return mg_task_text_int(out, cap, at, (int64_t)(tenths % 10u));
}

static const char *const JOINT_NAMES[6] = {"gripper", "wrist_roll", "wrist_pitch",
                                           "elbow_pitch", "shoulder_pitch", "waist_yaw"};

size_t mg_task_ik_reason(const mg_arm_geometry_t *g, int32_t code, int64_t detail,
                         const mg_arm_pose_t *pose, char *out, size_t cap, size_t at)
{
    const int64_t l1 = g->l1_mm_q4, l2 = g->l2_mm_q4;
    switch (code) {
    case MG_IK_ON_AXIS:
        return mg_task_text(out, cap, at, "target on the waist axis: waist angle undefined");
    case MG_IK_OUT_OF_REACH:
    case MG_IK_TOO_CLOSE:
        at = mg_task_text(out, cap, at, code == MG_IK_OUT_OF_REACH ? "out of reach: wrist point "
                                                                   : "too close: wrist point ");
        at = mg_task_text_q4_1(out, cap, at, detail);
        at = mg_task_text(out, cap, at, code == MG_IK_OUT_OF_REACH
                                            ? " mm from the shoulder > l1 + l2 = "
                                            : " mm from the shoulder < |l1 - l2| = ");
        at = mg_task_text_q4_1(out, cap, at,
                               code == MG_IK_OUT_OF_REACH ? l1 + l2 : (l1 > l2 ? l1 - l2 : l2 - l1));
        return mg_task_text(out, cap, at, " mm");
    case MG_IK_JOINT_LIMIT: {
        const int32_t ch = (int32_t)detail;
        const int32_t val[4] = {pose->theta2_mrad, pose->theta3_mrad, pose->theta4_mrad,
                                pose->theta5_mrad};
        at = mg_task_text(out, cap, at, "theta");
        at = mg_task_text_int(out, cap, at, ch);
        at = mg_task_text(out, cap, at, " (");
        at = mg_task_text(out, cap, at, ch >= 2 && ch <= 5 ? JOINT_NAMES[ch] : "?");
        at = mg_task_text(out, cap, at, ") would be ");
        at = mg_task_text_int(out, cap, at, ch >= 2 && ch <= 5 ? val[ch - 2] : 0);
        at = mg_task_text(out, cap, at, " mrad, outside [");
        at = mg_task_text_int(out, cap, at, mg_joint_lo_mrad(ch));
        at = mg_task_text(out, cap, at, ", ");
        at = mg_task_text_int(out, cap, at, mg_joint_hi_mrad(ch));
        return mg_task_text(out, cap, at, "] mrad");
    }
    default:
        at = mg_task_text(out, cap, at, "at the joint limits the point misses the target by ");
        at = mg_task_text_q4_1(out, cap, at, detail);
        return mg_task_text(out, cap, at, " mm");
    }
}

void mg_task_note(mg_task_t *t, const char *key, const char *json)
{
    int32_t i = 0, long_used = 0;
    while (i < t->n_notes && strcmp(t->notes[i].key, key) != 0)
        i++;
    for (int32_t k = 0; k < t->n_notes; k++)
        long_used |= k != i && t->notes[k].is_long;
    if (i == t->n_notes && t->n_notes == MG_TASK_NOTES) {
        t->notes_lost++;
        return;
    }
    const size_t nk = strlen(key), nj = strlen(json);
    const int is_long = nj >= sizeof t->notes[i].json;
    if (nk >= sizeof t->notes[i].key
        || (is_long && (long_used || nj >= sizeof t->long_note))) {
        t->notes_lost++;
        return;
    }
    memcpy(t->notes[i].key, key, nk + 1);
    memcpy(is_long ? t->long_note : t->notes[i].json, json, nj + 1);
    t->notes[i].is_long = is_long;
    if (i == t->n_notes)
        t->n_notes++;
}

const char *mg_task_note_json(const mg_task_t *t, int32_t i)
{
    return t->notes[i].is_long ? t->long_note : t->notes[i].json;
}

void mg_task_note_int(mg_task_t *t, const char *key, int64_t v)
{
    char text[24];
    mg_task_text_int(text, sizeof text, 0, v);
    mg_task_note(t, key, text);
}

void mg_task_note_ints(mg_task_t *t, const char *key, int32_t n, const char *const *names,
                       const int64_t *values)
{
    char text[MG_TASK_NOTE_BYTES];
    mg_json_t j;
    mg_json_init(&j, text, sizeof text - 1);
    mg_json_begin_object(&j);
    for (int32_t i = 0; i < n; i++) {
        mg_json_key(&j, names[i]);
        mg_json_int(&j, values[i]);
    }
    mg_json_end_object(&j);
    mg_json_terminate(&j);
    mg_task_note(t, key, text);
}

void mg_task_gripper_point_q4(const mg_task_t *t, int32_t out_q4[3])
{
    mg_fk_mm_q4(&t->geom, t->arm[2], t->arm[3], t->arm[4], t->arm[5], out_q4);
}

void mg_task_apply_pose(mg_task_t *t, int64_t now_us, const mg_arm_pose_t *pose,
                        int32_t has_th1, int32_t th1)
{
    mg_task_set_arm(t, now_us, pose->theta2_mrad, pose->theta3_mrad, pose->theta4_mrad,
                    pose->theta5_mrad, has_th1, th1);
}

/* APPROACH (approach.py): the method's entry (after the common reset) and step */
static void enter_approach(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    if (t->rules->enter_approach)
        t->rules->enter_approach(t, now_us, in);
}

static void do_approach(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    if (t->rules->approach)
        t->rules->approach(t, now_us, in);
}

/* ADJUST (adjust.py) on the frame's result of the method's adjust detector */
static void enter_adjust(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    (void)in;
    mg_task_enter_adjust(t, now_us);
}

static void do_adjust(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    const struct mg_task_method *r = t->rules;
    mg_task_do_adjust(t, now_us, in, r->adjust_result ? r->adjust_result(in) : NULL,
                      r->radial_result ? r->radial_result(in) : NULL);
}

/* each state's entry action and step (machine.py ENTRY, STEP); the terminal states have
 * neither */
static const mg_task_state_fn ENTRY[MG_N_TASK_STATES] = {
    mg_task_enter_search, enter_approach, enter_adjust,
    mg_task_enter_rough_grasp, mg_task_enter_precise_grasp, mg_task_enter_lift, NULL,
    mg_task_enter_lost, NULL};
static const mg_task_state_fn STEP[MG_N_TASK_STATES] = {
    mg_task_do_search, do_approach, do_adjust, mg_task_do_rough_grasp,
    mg_task_do_precise_grasp, mg_task_do_lift, NULL, mg_task_do_lost, NULL};

int mg_task_init(mg_task_t *t, const mg_task_method_t *rules, const mg_task_params_t *p,
                 int64_t start_us)
{
    if (rules->ms_bytes > MG_TASK_MS_BYTES)
        return -1;
    memset(t, 0, sizeof *t);
    t->rules = rules;
    t->p = *p;
    t->cam = rules->camera;
    t->geom = rules->geom;
    t->state = MG_SEARCH;
    t->entered_us = start_us;
    t->entry_pending = 1;
    memcpy(t->arm, HOME_ARM, sizeof t->arm);
    memcpy(t->joints, HOME_ARM, sizeof t->joints);
    t->move_done_us = start_us;
    t->obj_seen_us = start_us;
    /* the object itself seen, or its place P_i given (001 section II; machine.py) */
    t->graspable_seen = p->has_object_xy;
    t->lost_in = -1;
    t->path.plan_us = start_us;
    t->grasp_alpha_mrad = rules->grasp_alpha_mrad;
    memcpy(t->entry, ENTRY, sizeof t->entry);
    memcpy(t->step, STEP, sizeof t->step);
    rules->ms_init(t->ms.bytes);
    return 0;
}

/* Transition (logged); entering a state runs its entry action on the next step. */
void mg_task_go(mg_task_t *t, int64_t now_us, int32_t to, const char *why)
{
    if (t->n_events < MG_TASK_EVENTS) {
        mg_task_event_t *e = &t->events[t->n_events++];
        e->t_us = now_us;
        e->from = t->state;
        e->to = to;
        mg_task_text(e->why, sizeof e->why, 0, why);
    } else {
        t->events_lost++;
    }
    t->state = to;
    t->entered_us = now_us;
    t->entry_pending = 1;
}

void mg_task_fail(mg_task_t *t, int64_t now_us, const char *reason)
{
    t->rules->failure_reason(t, reason, t->failure, sizeof t->failure);
    t->has_failure = 1;
    mg_task_go(t, now_us, MG_FAILED, t->failure);
}

void mg_task_set_arm(mg_task_t *t, int64_t now_us, int32_t th2, int32_t th3, int32_t th4,
                     int32_t th5, int32_t has_th1, int32_t th1)
{
    int32_t next[6] = {t->arm[0], has_th1 ? th1 : t->arm[1], th2, th3, th4, th5};
    int64_t travel = 0;
    for (int32_t ch = 0; ch < 6; ch++)
        next[ch] = mg_clamp_mrad(ch, next[ch]);
    for (int32_t ch = 1; ch < 6; ch++) {
        const int64_t d = (int64_t)next[ch] - t->arm[ch];
        if ((d < 0 ? -d : d) > travel)
            travel = d < 0 ? -d : d;
    }
    memcpy(t->arm, next, sizeof t->arm);
    const int64_t done = now_us + travel * 1000000 / t->p.servo_speed_mrad_per_s
                         + t->p.settle_margin_us;
    const int64_t from = travel == 0 ? t->move_done_us : now_us;
    t->move_done_us = from > done ? from : done;
}

int mg_task_settled(const mg_task_t *t, int64_t now_us)
{
    return now_us >= t->move_done_us;
}

/* The histories are rings of MG_TASK_HIST entries from their oldest, *_hist_first: an entry is
 * added and the oldest dropped in place, each step (shifting the second's ~50 entries down
 * each step cost the ARM920T ~10 us of a control step). */
typedef char hist_is_a_power_of_two[(MG_TASK_HIST & (MG_TASK_HIST - 1)) == 0 ? 1 : -1];

static int32_t slot(int32_t first, int32_t i)
{
    return (first + i) & (MG_TASK_HIST - 1);
}

/* room for one more entry of a history: its oldest dropped when it is full (counted) */
static void make_room(mg_task_t *t, int32_t *first, int32_t *n)
{
    if (*n == MG_TASK_HIST) {
        *first = slot(*first, 1);
        (*n)--;
        t->hist_overflow++;
    }
}

/* the entries older than a second dropped, but for the last one at or before it */
static void drop_old(const int64_t *times, int32_t *first, int32_t *n, int64_t now_us)
{
    while (*n > 1 && times[slot(*first, 1)] <= now_us - 1000000) {
        *first = slot(*first, 1);
        (*n)--;
    }
}

/* Keep the last second of arm targets and base poses: a detection describes the frame
 * captured frame_latency_us ago (capture + vision), not the arm and base of now. */
void mg_task_remember(mg_task_t *t, int64_t now_us, int32_t x_mm, int32_t y_mm,
                      int32_t heading_mrad)
{
    if (t->n_arm_hist == 0
        || memcmp(t->arm_hist[slot(t->arm_hist_first, t->n_arm_hist - 1)], t->arm,
                  sizeof t->arm)) {
        make_room(t, &t->arm_hist_first, &t->n_arm_hist);
        const int32_t k = slot(t->arm_hist_first, t->n_arm_hist++);
        t->arm_hist_t[k] = now_us;
        memcpy(t->arm_hist[k], t->arm, sizeof t->arm);
    }
    make_room(t, &t->pose_hist_first, &t->n_pose_hist);
    const int32_t k = slot(t->pose_hist_first, t->n_pose_hist++);
    t->pose_hist_t[k] = now_us;
    t->pose_hist[k][0] = x_mm, t->pose_hist[k][1] = y_mm, t->pose_hist[k][2] = heading_mrad;
    drop_old(t->arm_hist_t, &t->arm_hist_first, &t->n_arm_hist, now_us);
    drop_old(t->pose_hist_t, &t->pose_hist_first, &t->n_pose_hist, now_us);
}

/* the slot of the last entry at or before t_us, else of the first */
static int32_t at(const int64_t *times, int32_t first, int32_t n, int64_t t_us)
{
    int32_t best = 0;
    for (int32_t i = 0; i < n; i++)
        if (times[slot(first, i)] <= t_us)
            best = i;
    return slot(first, best);
}

void mg_task_arm_at(const mg_task_t *t, int64_t t_us, int32_t arm[6])
{
    if (t->n_arm_hist == 0)
        memcpy(arm, t->arm, sizeof t->arm);
    else
        memcpy(arm, t->arm_hist[at(t->arm_hist_t, t->arm_hist_first, t->n_arm_hist, t_us)],
               sizeof t->arm);
}

int mg_task_pose_at(const mg_task_t *t, int64_t t_us, int64_t *at_us, int32_t pose[3])
{
    if (t->n_pose_hist == 0)
        return 0;
    const int32_t i = at(t->pose_hist_t, t->pose_hist_first, t->n_pose_hist, t_us);
    *at_us = t->pose_hist_t[i];
    memcpy(pose, t->pose_hist[i], sizeof t->pose_hist[i]);
    return 1;
}

void mg_task_obj_platform(const mg_task_t *t, const mg_task_inputs_t *in, int32_t out_q4[2])
{
    mg_odom_to_platform_q4(in->x_mm, in->y_mm, in->heading_mrad, t->p.mount_forward_mm,
                           t->obj_mm[0], t->obj_mm[1], out_q4);
}

void mg_task_look_at_object(mg_task_t *t, const mg_task_inputs_t *in, int32_t top)
{
    if (!t->has_obj)
        return;
    int32_t xy[2];
    mg_task_obj_platform(t, in, xy);
    const int32_t look_mm = t->rules->look_height_mm(&t->p, top);
    const int32_t obj[3] = {xy[0], xy[1], (look_mm - t->p.h_shoulder_mm) * 16};
    const mg_posture_params_t pp = mg_task_posture_params(t, t->p.posture_step_mrad);
    mg_posture_adjustment_t adj;
    mg_adjust_posture(&t->geom, &t->arm[2], obj, &pp, 0, 0, &adj);
    t->arm[2] = adj.theta2_mrad;
    t->arm[3] = adj.theta3_mrad;
    t->arm[4] = adj.theta4_mrad;
    t->arm[5] = adj.theta5_mrad;
}

mg_posture_params_t mg_task_posture_params(const mg_task_t *t, int32_t max_step_mrad)
{
    mg_posture_params_t pp = t->p.posture;
    pp.max_step_mrad = max_step_mrad;
    return pp;
}

/* Keep both "+" in the odometry frame: the precise grasp looks at one of them (000: "only a
 * '+' symbol is used in the precise grasping"); a pair not ~47.3 mm apart is a bad one. */
static void remember_plus(mg_task_t *t, const mg_plus_seen_t *det, const int32_t joints[6],
                          const int32_t pose[3])
{
    int32_t pair[2][3];
    const int32_t top = (t->p.object_top_mm - t->p.h_shoulder_mm) * 16;
    if (!mg_plus_positions(&t->geom, joints, &t->cam, det->uv_q4, det->dist_mm,
                           t->rules->plus_on_top, top, pair))
        return;
    const int64_t dx = (int64_t)pair[0][0] - pair[1][0], dy = (int64_t)pair[0][1] - pair[1][1];
    const int64_t d = mg_isqrt(dx * dx + dy * dy);
    if (d < 30 * 16 || d > 65 * 16)
        return; /* not 47.3 mm apart: a bad pair */
    for (int32_t k = 0; k < 2; k++)
        mg_platform_to_odom_mm(pose[0], pose[1], pose[2], t->p.mount_forward_mm, pair[k],
                               t->plus_odom_mm[k]);
    t->has_plus_odom = 1;
}

int mg_task_see_object(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                       mg_task_position_fn position, const void *det, int32_t is_object)
{
    const int64_t t_cap = now_us - t->p.frame_latency_us;
    if (t_cap < t->trust_from_us)
        return 0; /* captured while the arm swung to a new posture: pose unknown */
    int32_t joints[6], pose[3] = {in->x_mm, in->y_mm, in->heading_mrad}, p[3];
    int64_t at_us;
    mg_task_arm_at(t, t_cap, joints);
    mg_task_pose_at(t, t_cap, &at_us, pose); /* without a history: the present pose */
    if (!position(t, joints, det, p)
        || mg_isqrt((int64_t)p[0] * p[0] + (int64_t)p[1] * p[1]) > 5000 * 16) {
        t->bad_detections++;
        return 0;
    }
    mg_platform_to_odom_mm(pose[0], pose[1], pose[2], t->p.mount_forward_mm, p, t->obj_mm);
    t->has_obj = 1;
    t->obj_seen_us = now_us;
    if (is_object)
        t->graspable_seen = t->object_sighted = 1;
    if (position == mg_task_plus_position)
        remember_plus(t, (const mg_plus_seen_t *)det, joints, pose);
    return 1;
}

int mg_task_sighting_position(const mg_task_t *t, const int32_t joints[6], const void *det,
                              int32_t p_q4[3])
{
    const mg_sighting_t *s = (const mg_sighting_t *)det;
    if (!s || s->depth_mm_q4 <= 0)
        return 0;
    mg_pixel_to_platform_mm_q4(&t->geom, joints, &t->cam, s->u_q4, s->v_q4, s->depth_mm_q4,
                               p_q4);
    return 1;
}

int mg_task_plus_position(const mg_task_t *t, const int32_t joints[6], const void *det,
                          int32_t p_q4[3])
{
    return mg_task_sighting_position(t, joints, &((const mg_plus_seen_t *)det)->sighting, p_q4);
}

/* the state's entry action once after a transition, then its step */
static void run_state(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    if (t->entry_pending) {
        t->entry_pending = 0;
        const int32_t state = t->state;
        if (t->entry[state])
            t->entry[state](t, now_us, in);
        if (t->state != state)
            return;
    }
    if (t->step[t->state])
        t->step[t->state](t, now_us, in);
}

void mg_task_step(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                  mg_task_outputs_t *out)
{
    t->n_events = 0;
    memset(&t->path.ops, 0, sizeof t->path.ops); /* the step's planning work */
    t->n_notes = 0;
    /* joints from telemetry; without telemetry assume the arm is where it was sent */
    memcpy(t->joints, in->has_joints ? in->joints_mrad : t->arm, sizeof t->joints);
    if (!mg_task_terminal(t->state)) {
        const int64_t limit = t->p.timeouts_us[t->state];
        if (limit >= 0 && now_us - t->entered_us >= limit) {
            char why[MG_TASK_WHY];
            size_t n = mg_task_text(why, sizeof why, 0, "timeout: ");
            n = mg_task_text(why, sizeof why, n, mg_task_state_name(t->state));
            n = mg_task_text(why, sizeof why, n, " exceeded ");
            n = mg_task_text_int(why, sizeof why, n, limit);
            mg_task_text(why, sizeof why, n, " us");
            mg_task_fail(t, now_us, why);
        }
    }
    if (!mg_task_terminal(t->state)) {
        run_state(t, now_us, in);
        if (t->rules->guard_wheels)
            t->rules->guard_wheels(t, now_us, in);
        mg_task_remember(t, now_us, in->x_mm, in->y_mm, in->heading_mrad);
    }
    if (mg_task_terminal(t->state))
        t->wheels[0] = t->wheels[1] = 0;
    out->servo_mrad[0] = mg_clamp_mrad(0, t->gripper);
    for (int32_t ch = 1; ch < 6; ch++)
        out->servo_mrad[ch] = mg_clamp_mrad(ch, t->arm[ch]);
    out->wheels_mmps[0] = t->wheels[0];
    out->wheels_mmps[1] = t->wheels[1];
    out->gripper_permille = t->gripper;
    out->state = t->state;
}
