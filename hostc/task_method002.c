/* Paper 002's method: double cross, fuzzy approach, red cylinder, the level gripper
 * (host/task/method002.py). */
#include "task_method002.h"

#include <string.h>

#include "app_factory.h"
#include "fixedpoint.h"
#include "json.h"
#include "kernels.h"
#include "ranging.h"
#include "posture.h"
#include "trig.h"
#include "task_drive.h"
#include "task_grasp.h"
#include "task_method.h"
#include "task_sense.h"

static mg_state002_t *ms002(mg_task_t *t)
{
    return (mg_state002_t *)(void *)t->ms.bytes;
}

void mg_method002_ms_init(void *ms)
{
    memset(ms, 0, sizeof(mg_state002_t));
}

/* TaskParams.for_method("002"): the defaults with 002's own (method002.py param_defaults) */
void mg_method002_params(mg_task_params_t *p)
{
    mg_task_params_default(p);
    p->h_shoulder_mm = 50;
    p->object_top_mm = 120;
    p->grasp_height_mm = 100;
    p->grasp_r_mm = 255;
    p->grasp_r_tol_mm = 15;
    p->pregrasp_back_mm = 40;
    /* the double cross stands upright, far: the paper's first cycle, then the level look
     * (f = 350 px: 0.66 rad vertical field); the wander gives up past the disc of 2.5 m */
    p->search.dense_cycles = 1;
    p->search.n_coarse = 2;
    p->search.coarse_theta2_mrad[0] = -2100;
    p->search.coarse_theta2_mrad[1] = -2400;
    p->search.cover_mm = MG_SEARCH_COVER_002_MM;
    /* ADJUST's look: d_pixel passes T_d with the axis inside the level grasp's reach */
    p->adjust_theta3_mrad = -2190;
    p->adjust_theta4_mrad = 2120;
    p->posture.margin_mode = MG_MARGIN_LIMITS; /* the printed theta2m leaves no room at 0 */
}

int mg_method002_object_cue_seen(const mg_task_t *t)
{
    return ((const mg_state002_t *)(const void *)t->ms.bytes)->red_seen != 0;
}

/* A run that never saw the red cylinder (a board alone) says so whatever ended it. */
void mg_method002_failure_reason(const mg_task_t *t, const char *reason, char *out, size_t cap)
{
    static const char GIVEN_UP[] = "no graspable object found";
    if (t->graspable_seen || strncmp(reason, GIVEN_UP, sizeof GIVEN_UP - 1) == 0) {
        mg_task_text(out, cap, 0, reason);
        return;
    }
    const size_t n = mg_task_text(out, cap, 0,
                                  "no graspable object found (red_cylinder never seen): ");
    mg_task_text(out, cap, n, reason);
}

int mg_method002_found(mg_task_t *t, int64_t now_us, const mg_sighting002_t *s)
{
    mg_state002_t *ms = ms002(t);
    int32_t joints[6];
    mg_task_arm_at(t, now_us - t->p.frame_latency_us, joints);
    /* the column's bearing from the waist of the frame (level roll: the pitch does not turn
     * the image), the double cross's midpoint or the ROI's centre */
    ms->e_mrad = mg_bearing_mrad(s->u_q4, joints[5], &t->cam);
    t->obj_seen_us = now_us;
    ms->steer_on = s->steer_on;
    ms->has_e_dpx = s->steer_on == MG_STEER_DOUBLE_CROSS;
    ms->e_dpx = ms->has_e_dpx ? mg_d_pixel_px(s->d_pixel_q4) : 0;
    ms->has_e_range = s->steer_on == MG_STEER_RED_CYLINDER && s->has_range;
    ms->e_range_mm = ms->has_e_range ? s->range_mm : 0;
    return 1;
}

void mg_method002_found_why(const mg_task_t *t, char *why, size_t cap)
{
    const mg_state002_t *ms = (const mg_state002_t *)(const void *)t->ms.bytes;
    const int cross = ms->steer_on == MG_STEER_DOUBLE_CROSS;
    size_t n = mg_task_text(why, cap, 0, cross ? "double cross seen at e = "
                                               : "red cylinder's colour ROI seen at e = ");
    n = mg_task_text_int(why, cap, n, ms->e_mrad);
    mg_task_text(why, cap, n, cross ? " mrad" : " mrad (no double cross in view)");
}

/* horizontal first; the world accepts |alpha| < 0.3 */
static const int32_t GRASP_ALPHAS_002[] = {0, -100, -200, -280};

int mg_method002_grasp_reach_mm(const mg_task_t *t, int32_t *centre_mm, int32_t *half_mm)
{
    const int32_t z = (t->p.grasp_height_mm - t->p.h_shoulder_mm) * 16;
    int32_t lo = 0, hi = 0, any = 0;
    for (int32_t r = MG_LEVEL_SCAN_LO_MM; r <= MG_LEVEL_SCAN_HI_MM;
         r += MG_LEVEL_SCAN_STEP_MM) {
        const int32_t target[3] = {0, r * 16, z};
        mg_arm_pose_t pose;
        int64_t detail;
        if (mg_ik_pitch_mm_q4(&t->geom, target, 0, &pose, &detail) == MG_IK_OK) {
            lo = any ? lo : r;
            hi = r;
            any = 1;
        }
    }
    if (!any)
        return 0;
    *centre_mm = (lo + hi) / 2;
    const int32_t half = (hi - lo) / 2 - MG_LEVEL_MARGIN_MM;
    *half_mm = half > 1 ? half : 1;
    return 1;
}

int32_t mg_method002_grasp_ik(const mg_arm_geometry_t *g, const int32_t target_q4[3],
                              mg_arm_pose_t *pose, int64_t *detail)
{
    int32_t first = MG_IK_OK;
    int64_t first_detail = 0;
    for (size_t i = 0; i < sizeof GRASP_ALPHAS_002 / sizeof GRASP_ALPHAS_002[0]; i++) {
        const int32_t code = mg_ik_pitch_mm_q4(g, target_q4, GRASP_ALPHAS_002[i], pose, detail);
        if (code == MG_IK_OK)
            return code;
        if (first == MG_IK_OK) {
            first = code;
            first_detail = *detail;
        }
    }
    *detail = first_detail;
    return first;
}

/* (reach mm ahead of the waist, height mm above the ground, camera pitch down mrad): a
 * cylinder left standing is then ~150 mm further out and below the view (docs/task.md) */
static const int32_t HELD_VIEWS_002[][3] = {
    {100, 160, 800}, {80, 160, 900}, {90, 160, 850}, {110, 155, 800}};

int mg_method002_held_view_pose(const mg_task_t *t, mg_arm_pose_t *pose)
{
    int32_t tip[3];
    mg_fk_mm_q4(&t->geom, t->arm[2], t->arm[3], t->arm[4], t->arm[5], tip);
    const int64_t rho = mg_isqrt((int64_t)tip[0] * tip[0] + (int64_t)tip[1] * tip[1]);
    if (rho <= 0)
        return 0;
    for (size_t i = 0; i < sizeof HELD_VIEWS_002 / sizeof HELD_VIEWS_002[0]; i++) {
        const int64_t r_q4 = (int64_t)HELD_VIEWS_002[i][0] * 16;
        const int32_t target[3] = {(int32_t)mg_floor_div(tip[0] * r_q4, rho),
                                   (int32_t)mg_floor_div(tip[1] * r_q4, rho),
                                   (HELD_VIEWS_002[i][1] - t->p.h_shoulder_mm) * 16};
        int64_t detail;
        if (mg_ik_pitch_mm_q4(&t->geom, target, -HELD_VIEWS_002[i][2], pose, &detail)
            == MG_IK_OK)
            return 1;
    }
    return 0;
}

int mg_method002_red_cylinder_position(const mg_task_t *t, const int32_t joints[6],
                                       const void *det, int32_t p_q4[3])
{
    const mg_red_cylinder_seen_t *rc = (const mg_red_cylinder_seen_t *)det;
    if (rc->d_pixel_q4 <= 0)
        return 0;
    if (joints[1] != 0) { /* rolled: the detector's pinhole sighting */
        const int64_t depth = (int64_t)MG_RING_D_MM_Q4 * t->cam.f_px * 16 / rc->d_pixel_q4;
        if (depth <= 0)
            return 0;
        mg_pixel_to_platform_mm_q4(&t->geom, joints, &t->cam, rc->u_c_q4, rc->v_c_q4,
                                   (int32_t)depth, p_q4);
        return 1;
    }
    int32_t fix[6], cam[3];
    if (!mg_locate_ring_pair(rc->d_pixel_q4, rc->u_c_q4, rc->v_c_q4, rc->width_q4,
                             joints[2] + joints[3] + joints[4], joints[5], t->cam.f_px,
                             t->cam.u0_px, t->cam.v0_px, MG_D_RING_UM, fix))
        return 0;
    mg_fk_mm_q4(&t->geom, joints[2], joints[3], joints[4], joints[5], cam);
    for (int i = 0; i < 3; i++)
        p_q4[i] = cam[i] + 16 * fix[i];
    return 1;
}

/* the two rings sit at mid-height: keep them, not the top, in view */
int32_t mg_method002_look_height_mm(const mg_task_params_t *p, int32_t top)
{
    return top ? p->object_top_mm / 2 : p->grasp_height_mm;
}

int32_t mg_method002_board_range_mm(const mg_task_t *t, int32_t d_px)
{
    return (int32_t)mg_floor_div((int64_t)MG_CROSS_SPACING_MM_Q4 * t->cam.f_px,
                                 16 * (int64_t)d_px);
}

void mg_method002_enter_approach(mg_task_t *t, const mg_task_inputs_t *in)
{
    mg_state002_t *ms = ms002(t);
    mg_fuzzy_approach_init(&ms->fuzzy, &t->p.fuzzy);
    ms->has_fuzzy = 1;
    if (ms->has_e_dpx && ms->e_dpx)
        mg_method002_remember_bearing(t, in, ms->e_mrad, 1,
                                      mg_method002_board_range_mm(t, ms->e_dpx));
    else
        mg_method002_remember_bearing(t, in, ms->e_mrad, ms->has_e_range, ms->e_range_mm);
}

/* The bearing to steer on blind should the next frames miss the board or the cylinder, and
 * how far: at most blind_approach_mm, and blind_keep_mm short of the range of what was seen. */
void mg_method002_remember_bearing(mg_task_t *t, const mg_task_inputs_t *in, int32_t e_mrad,
                                   int32_t has_cue, int32_t cue_mm)
{
    mg_state002_t *ms = ms002(t);
    ms->has_blind = 0;
    if (!has_cue || cue_mm <= 0)
        return;
    const int64_t keep = (int64_t)cue_mm - t->p.blind_keep_mm;
    const int64_t reach = keep < t->p.blind_approach_mm ? keep : t->p.blind_approach_mm;
    if (reach > 0) {
        ms->has_blind = 1;
        ms->blind[0] = in->heading_mrad - e_mrad;
        ms->blind[1] = in->x_mm;
        ms->blind[2] = in->y_mm;
        ms->blind[3] = (int32_t)reach;
    }
}

static int32_t clamp32(int64_t v, int32_t lo, int32_t hi)
{
    return (int32_t)(v < lo ? lo : v > hi ? hi : v);
}

/* the fuzzy approach's trace detail: e, its rate e_c (has_ec 0: none), u, the wheels, what it
 * steered on (NULL: nothing) or blind */
static void note_fuzzy(mg_task_t *t, int32_t has_e, int32_t e, int32_t has_ec, int64_t ec,
                       int32_t u_mrad, const char *steer_on, int32_t blind)
{
    char text[MG_TASK_NOTE_BYTES];
    mg_json_t j;
    mg_json_init(&j, text, sizeof text - 1);
    mg_json_begin_object(&j);
    if (blind) {
        mg_json_key(&j, "blind");
        mg_json_bool(&j, 1);
    }
    mg_json_key(&j, "e_c_mrad_s");
    if (has_ec)
        mg_json_int(&j, ec);
    else
        mg_json_null(&j);
    mg_json_key(&j, "e_mrad");
    if (has_e)
        mg_json_int(&j, e);
    else
        mg_json_null(&j);
    if (!blind) {
        mg_json_key(&j, "steer_on");
        if (steer_on)
            mg_json_string(&j, steer_on, strlen(steer_on));
        else
            mg_json_null(&j);
    }
    mg_json_key(&j, "u_mrad");
    mg_json_int(&j, u_mrad);
    mg_json_key(&j, "wheels_mmps");
    mg_json_int_pair(&j, t->wheels[0], t->wheels[1]);
    mg_json_end_object(&j);
    mg_json_terminate(&j);
    mg_task_note(t, "fuzzy", text);
}

/* No marker in this frame: steer on the bearing it was last seen at, by odometry, for up to
 * the remembered reach and blind_approach_us (ours, not 002's: its fuzzy loop assumes the
 * marker always in view, docs/cosim.md "Measured", T7). The fuzzy step is eq. (1), (2). */
int mg_method002_approach_blind(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                                int32_t *u_mrad)
{
    mg_state002_t *ms = ms002(t);
    if (!ms->has_blind)
        return 0;
    const int64_t dx = (int64_t)in->x_mm - ms->blind[1], dy = (int64_t)in->y_mm - ms->blind[2];
    if (mg_isqrt(dx * dx + dy * dy) >= ms->blind[3]
        || now_us - t->obj_seen_us >= t->p.blind_approach_us)
        return 0;
    const int32_t e = mg_task_wrap_mrad((int64_t)in->heading_mrad - ms->blind[0]);
    const mg_fuzzy_command_t cmd = mg_fuzzy_approach_step(&ms->fuzzy, now_us, 1, e, 0, 0);
    t->wheels[0] = cmd.left_mm_s;
    t->wheels[1] = cmd.right_mm_s;
    mg_task_set_arm(t, now_us, t->arm[2], t->arm[3], t->arm[4], clamp32(e, -800, 800), 0, 0);
    ms->has_prev_e = 0;
    *u_mrad = cmd.u_mrad;
    note_fuzzy(t, 1, e, 0, 0, cmd.u_mrad, NULL, 1);
    return 1;
}

/* No cue in this frame while the sonar guard drives the base out of R_r, or after it until
 * the base faces the cylinder's estimate again (turning in place, by odometry): 1 meanwhile,
 * the lost timeout counted from then (the drive out turns the base away on purpose;
 * host/task/method002.py looks_back). */
static int looks_back(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    mg_state002_t *ms = ms002(t);
    if (t->guard_out.active) {
        ms->look_back = t->has_obj;
        t->obj_seen_us = now_us;
        return 1;
    }
    if (!ms->look_back)
        return 0;
    int32_t xy[2];
    mg_task_obj_platform(t, in, xy);
    /* seen from the axle */
    const int32_t bearing = mg_atan2_mrad(xy[0], (int64_t)xy[1] + t->p.mount_forward_mm * 16);
    if ((bearing < 0 ? -bearing : bearing) <= t->p.bearing_tol_mrad) {
        ms->look_back = 0;
        return 0;
    }
    mg_task_turn_in_place(bearing > 0 ? -1 : 1, t->p.turn_wheel_mmps, t->wheels);
    t->obj_seen_us = now_us;
    static const char *const names[1] = {"bearing_mrad"};
    const int64_t values[1] = {bearing};
    mg_task_note_ints(t, "look_back", 1, names, values);
    return 1;
}

/* ADJUST's backstop by the estimate (the stop rule d_pixel > T_d of 002 section 4 stops it
 * first): the near end of the level grasp's reach, ADJUST_STALE_BACK_MM nearer until an
 * estimate of this ADJUST's look has come. */
int mg_method002_adjust_done_seen(mg_task_t *t, int64_t now_us, const void *det,
                                  int32_t dist_mm)
{
    const mg_red_cylinder_seen_t *rc = (const mg_red_cylinder_seen_t *)det;
    return mg_method002_adjust_done(t, now_us, 1, rc->d_pixel_q4, dist_mm);
}

void mg_method002_adjust_goal_mm(const mg_task_t *t, int32_t *goal_mm, int32_t *tol_mm)
{
    int32_t goal = t->p.grasp_r_mm - 25;
    if (t->obj_seen_us < t->trust_from_us + t->p.frame_latency_us)
        goal -= MG_ADJUST_STALE_BACK_MM;
    *goal_mm = goal;
    *tol_mm = 5;
}

int32_t mg_method002_adjust_vmax_mmps(const mg_task_params_t *p)
{
    return p->slow_mmps;
}

void mg_method002_track_marker(mg_task_t *t, int64_t now_us, int32_t has_vm, int32_t vm_q4,
                               int32_t e_mrad)
{
    /* a bigger jump is still under way when the next frame is taken, whose bearing then reads
     * the waist wrong (the yaw of a frame is the target the waist was sent) */
    const int32_t step = clamp32((int64_t)e_mrad - t->arm[5], -MG_WAIST_STEP_MRAD,
                                 MG_WAIST_STEP_MRAD);
    const int32_t th5 = clamp32((int64_t)t->arm[5] + step, -800, 800);
    int32_t d[3] = {0, 0, 0};
    if (has_vm) {
        const int32_t cap = t->p.posture_step_mrad;
        const int32_t d_alpha = clamp32(
            -(int64_t)mg_atan2_mrad((int64_t)vm_q4 - t->cam.v0_px * 16, t->cam.f_px * 16),
            -cap, cap);
        const mg_posture_params_t pp = mg_task_posture_params(t, cap);
        mg_distribute_alpha(d_alpha, t->arm[2], t->arm[3], t->arm[4], &pp, d);
    }
    mg_task_set_arm(t, now_us, t->arm[2] + d[0], t->arm[3] + d[1], t->arm[4] + d[2], th5, 0, 0);
}

/* v_q4 / 16 >= 0 to one decimal as Python's format(v / 16, ".1f") (ties to even: sixteenths
 * are exact binary fractions) */
static size_t text_q4_1(char *out, size_t cap, size_t at, int32_t v_q4)
{
    int64_t tenths = (int64_t)v_q4 * 10 / 16;
    const int64_t rem = (int64_t)v_q4 * 10 % 16;
    if (rem > 8 || (rem == 8 && (tenths & 1)))
        tenths++;
    at = mg_task_text_int(out, cap, at, tenths / 10);
    at = mg_task_text(out, cap, at, ".");
    return mg_task_text_int(out, cap, at, tenths % 10);
}

int mg_method002_adjust_done(mg_task_t *t, int64_t now_us, int32_t has_d, int32_t d_pixel_q4,
                             int32_t dist_mm)
{
    if (!has_d || now_us - t->p.frame_latency_us < t->trust_from_us)
        return 0; /* a frame taken before the arm settled in ADJUST's look does not count */
    if ((int64_t)d_pixel_q4 <= 16 * (int64_t)t->p.t_d_px)
        return 0;
    char why[MG_TASK_WHY];
    size_t n = mg_task_text(why, sizeof why, 0, "stop rule d_pixel > T_d: d_pixel = ");
    n = text_q4_1(why, sizeof why, n, d_pixel_q4);
    n = mg_task_text(why, sizeof why, n, " px > T_d = ");
    n = mg_task_text_int(why, sizeof why, n, t->p.t_d_px);
    n = mg_task_text(why, sizeof why, n, " px, red cylinder estimated ");
    n = mg_task_text_int(why, sizeof why, n, dist_mm);
    mg_task_text(why, sizeof why, n, " mm from the waist");
    t->wheels[0] = t->wheels[1] = 0;
    mg_task_go(t, now_us, MG_ROUGH_GRASP, why);
    return 1;
}

/* the estimate's distance from the waist, whole mm */
static int32_t obj_dist_mm(const mg_task_t *t, const mg_task_inputs_t *in)
{
    int32_t xy[2];
    mg_task_obj_platform(t, in, xy);
    return (int32_t)(mg_isqrt((int64_t)xy[0] * xy[0] + (int64_t)xy[1] * xy[1]) >> 4);
}

static void go_near(mg_task_t *t, int64_t now_us, const char *lead, int32_t lead_px,
                    int32_t dist_mm)
{
    char why[MG_TASK_WHY];
    size_t n = 0;
    if (lead) {
        n = mg_task_text(why, sizeof why, n, lead);
        n = mg_task_text_int(why, sizeof why, n, lead_px);
        n = mg_task_text(why, sizeof why, n, " px apart: ");
    }
    n = mg_task_text(why, sizeof why, n, "red cylinder estimated ");
    n = mg_task_text_int(why, sizeof why, n, dist_mm);
    mg_task_text(why, sizeof why, n, " mm from the waist");
    mg_task_go(t, now_us, MG_ADJUST, why);
}

/* the red ROI's box touches the frame's border (2 u0 x 2 v0 px): the cylinder not wholly in
 * view */
static int roi_cut(const mg_task_t *t, const mg_frame002_t *f)
{
    if (!f->has_roi)
        return 0;
    const int32_t *b = f->roi_box;
    return b[0] <= 0 || b[1] <= 0 || b[0] + b[2] >= 2 * t->cam.u0_px
           || b[1] + b[3] >= 2 * t->cam.v0_px;
}

/* The estimate would start ADJUST dist_mm from the waist, within MG_BACK_OFF_WITHIN_MM beyond
 * the grasp's reach, while the last frame showed the cylinder cut by the frame's border, its
 * rings not measured: back straight off MG_BACK_OFF_002_MM instead (at most
 * MG_BACK_OFFS_002 times) and look again; 1 when it does. */
static int backs_off(mg_task_t *t, const mg_task_inputs_t *in, int32_t dist_mm)
{
    mg_state002_t *ms = ms002(t);
    if (!ms->cut || ms->back_offs >= MG_BACK_OFFS_002
        || dist_mm > t->p.grasp_r_mm + MG_BACK_OFF_WITHIN_MM)
        return 0;
    ms->back_offs++;
    ms->has_back_off = 1;
    ms->back_off_from[0] = in->x_mm;
    ms->back_off_from[1] = in->y_mm;
    ms->back_off_has_ended = 0;
    t->wheels[0] = t->wheels[1] = -t->p.slow_mmps;
    static const char *const names[2] = {"dist_mm", "n"};
    const int64_t values[2] = {dist_mm, ms->back_offs};
    mg_task_note_ints(t, "back_off", 2, names, values);
    return 1;
}

/* The back-off under way: straight back at slow_mmps until MG_BACK_OFF_002_MM from where it
 * started, then still until a frame taken after it ended has come; 1 until then (that frame
 * is the approach's again, LOST counted from it). */
static int backing_off(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                       const mg_frame002_t *f)
{
    mg_state002_t *ms = ms002(t);
    if (!ms->back_off_has_ended) {
        const int64_t dx = (int64_t)in->x_mm - ms->back_off_from[0];
        const int64_t dy = (int64_t)in->y_mm - ms->back_off_from[1];
        if (dx * dx + dy * dy < (int64_t)MG_BACK_OFF_002_MM * MG_BACK_OFF_002_MM) {
            t->wheels[0] = t->wheels[1] = -t->p.slow_mmps;
            return 1;
        }
        ms->back_off_has_ended = 1;
        ms->back_off_ended_us = now_us;
    }
    t->wheels[0] = t->wheels[1] = 0;
    if (!f->has_frame || now_us - t->p.frame_latency_us < ms->back_off_ended_us)
        return 1;
    ms->has_back_off = 0;
    t->obj_seen_us = now_us;
    return 0;
}

/* The board without its cylinder (method002.py board_alone): MG_BOARD_ALONE_FRAMES frames of
 * the crosses within MG_BOARD_ALONE_*_MM by their spacing and no red, before the red cylinder
 * was seen in any frame of the approach: FAILED "no graspable object found" (1). */
static int board_alone(mg_task_t *t, int64_t now_us, const mg_frame002_t *f)
{
    mg_state002_t *ms = ms002(t);
    if (ms->red_seen || t->graspable_seen)
        return 0;
    if (f->has_rc || f->has_roi) {
        ms->red_seen = 1;
        return 0;
    }
    const int32_t d_px = f->has_dc ? mg_d_pixel_px(f->dc_d_pixel_q4) : 0;
    if (!d_px)
        return 0;
    const int32_t range_mm = mg_method002_board_range_mm(t, d_px);
    if (range_mm < MG_BOARD_ALONE_MIN_MM || range_mm > MG_BOARD_ALONE_MAX_MM)
        return 0;
    if (++ms->alone_frames < MG_BOARD_ALONE_FRAMES)
        return 0;
    char why[MG_TASK_WHY];
    size_t n = mg_task_text(why, sizeof why, 0,
                            "no graspable object found: the double cross seen in ");
    n = mg_task_text_int(why, sizeof why, n, ms->alone_frames);
    n = mg_task_text(why, sizeof why, n, " frames ");
    n = mg_task_text_int(why, sizeof why, n, MG_BOARD_ALONE_MIN_MM);
    n = mg_task_text(why, sizeof why, n, "-");
    n = mg_task_text_int(why, sizeof why, n, MG_BOARD_ALONE_MAX_MM);
    mg_task_text(why, sizeof why, n, " mm away, no red cylinder before it");
    mg_task_fail(t, now_us, why);
    return 1;
}

void mg_method002_approach(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                           const mg_frame002_t *f, int32_t *has_u, int32_t *u_mrad)
{
    mg_state002_t *ms = ms002(t);
    *has_u = 0;
    if (ms->has_back_off && backing_off(t, now_us, in, f))
        return;
    if (f->has_frame)
        ms->cut = !f->has_rc && roi_cut(t, f);
    const int32_t d_px = f->has_rc ? mg_d_pixel_px(f->rc.d_pixel_q4) : 0;
    if (f->has_rc
        && mg_task_see_object(t, now_us, in, mg_method002_red_cylinder_position, &f->rc, 1)
        && d_px >= t->p.cylinder_near_px) {
        char why[MG_TASK_WHY];
        size_t n = mg_task_text(why, sizeof why, 0, "red cylinder seen, d_pixel = ");
        n = mg_task_text_int(why, sizeof why, n, d_px);
        mg_task_text(why, sizeof why, n, " px");
        mg_task_go(t, now_us, MG_ADJUST, why);
        return;
    }
    if (!f->has_rc && f->has_roi && f->has_roi_sighting) /* far: the range by the ROI's height */
        mg_task_see_object(t, now_us, in, mg_task_sighting_position, &f->roi_sighting, 0);
    if (t->has_obj) { /* the cylinder stands before the marker: do not run it over */
        const int32_t dist = obj_dist_mm(t, in);
        if (dist <= t->p.grasp_r_mm + 150) {
            if (!backs_off(t, in, dist))
                go_near(t, now_us, NULL, 0, dist);
            return;
        }
    }
    if (!f->has_frame)
        return; /* no new frame: keep the wheels as they are */
    if (board_alone(t, now_us, f))
        return;
    int32_t yaw[6];
    mg_task_arm_at(t, now_us - t->p.frame_latency_us, yaw); /* the waist of the frame */
    int32_t has_e = 0, e = 0, vm = 0, has_cue = 0, cue_mm = 0;
    const char *cue = NULL;
    if (f->has_dc) {
        has_e = 1;
        cue = "double cross";
        e = mg_bearing_mrad(f->dc_um_q4, yaw[5], &t->cam);
        vm = f->dc_vm_q4;
        const int32_t spacing = mg_d_pixel_px(f->dc_d_pixel_q4);
        has_cue = spacing != 0;
        cue_mm = spacing ? mg_method002_board_range_mm(t, spacing) : 0;
    } else if (f->has_rc || f->has_roi) {
        /* the double cross out of view: steer on the cylinder's column, its rings near, its
         * colour ROI far (ours: 002 steers on the board alone) */
        has_e = 1;
        cue = f->has_rc ? "red_cylinder" : "red_roi";
        e = mg_bearing_mrad(f->has_rc ? f->rc.u_c_q4 : f->roi_u_c_q4, yaw[5], &t->cam);
        vm = f->has_rc ? f->rc.v_c_q4 : f->roi_v_c_q4;
        has_cue = !f->has_rc && f->has_roi_sighting;
        cue_mm = has_cue ? f->roi_sighting.depth_mm_q4 >> 4 : 0;
    }
    if (!has_e && looks_back(t, now_us, in))
        return;
    if (!has_e && mg_method002_approach_blind(t, now_us, in, u_mrad)) {
        *has_u = 1;
        return;
    }
    if (!has_e && now_us - t->obj_seen_us >= t->p.lost_timeout_us) {
        char why[MG_TASK_WHY];
        size_t n = mg_task_text(why, sizeof why, 0,
                                "neither the double cross nor the red cylinder seen for ");
        n = mg_task_text_int(why, sizeof why, n, now_us - t->obj_seen_us);
        mg_task_text(why, sizeof why, n, " us");
        mg_task_go(t, now_us, MG_LOST, why);
        return;
    }
    const int32_t dc_px = f->has_dc ? mg_d_pixel_px(f->dc_d_pixel_q4) : 0;
    if (f->has_dc && dc_px >= t->p.cross_near_px && f->dc_level
        && mg_task_see_object(t, now_us, in, mg_task_sighting_position,
                              f->has_dc_sighting ? &f->dc_sighting : NULL, 0)) {
        /* near, the cylinder may be below the level look while the board is big in view: its
         * estimate from the crosses ends the approach (docs/cosim.md "Measured", T5); a pair
         * far from level is not the board's crosses (docs/task.md) */
        const int32_t dist = obj_dist_mm(t, in);
        if (dist <= t->p.grasp_r_mm + 150) {
            if (!backs_off(t, in, dist))
                go_near(t, now_us, "crosses ", dc_px, dist);
            return;
        }
    }
    const mg_fuzzy_command_t cmd = mg_fuzzy_approach_step(&ms->fuzzy, now_us, has_e, e, 0, 0);
    if (has_e) {
        t->obj_seen_us = now_us;
        ms->look_back = 0;
        mg_method002_remember_bearing(t, in, e, has_cue, cue_mm);
        mg_method002_track_marker(t, now_us, 1, vm, e);
    }
    t->wheels[0] = cmd.left_mm_s;
    t->wheels[1] = cmd.right_mm_s;
    const int32_t has_ec = has_e && ms->has_prev_e && now_us > ms->prev_e_t_us;
    const int64_t ec = has_ec ? mg_floor_div(((int64_t)e - ms->prev_e_mrad) * 1000000,
                                             now_us - ms->prev_e_t_us)
                              : 0;
    ms->has_prev_e = has_e;
    ms->prev_e_t_us = now_us;
    ms->prev_e_mrad = e;
    *has_u = 1;
    *u_mrad = cmd.u_mrad;
    note_fuzzy(t, has_e, e, has_ec, ec, cmd.u_mrad, cue, 0);
}

/* ---- the hooks of the machine's states (the method row) ---- */

int mg_method002_search_sighting(const mg_task_t *t, const mg_task_inputs_t *in, void *sighting)
{
    (void)t;
    const mg_frame002_t *f = (const mg_frame002_t *)in->frame;
    mg_sighting002_t *s = (mg_sighting002_t *)sighting;
    memset(s, 0, sizeof *s);
    if (f == NULL)
        return 0;
    if (f->has_dc) { /* the double cross when this frame shows it (002 section 2.1) */
        s->steer_on = MG_STEER_DOUBLE_CROSS;
        s->u_q4 = f->dc_um_q4;
        s->d_pixel_q4 = f->dc_d_pixel_q4;
        return 1;
    }
    if (!f->has_roi) /* else the red cylinder's colour ROI (002 section 2.2 step 1) */
        return 0;
    s->steer_on = MG_STEER_RED_CYLINDER;
    s->u_q4 = f->roi_u_c_q4;
    s->has_range = f->has_roi_sighting;
    s->range_mm = f->has_roi_sighting ? f->roi_sighting.depth_mm_q4 >> 4 : 0;
    return 1;
}

int mg_method002_found_seen(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                            const void *sighting)
{
    (void)in;
    return mg_method002_found(t, now_us, (const mg_sighting002_t *)sighting);
}

/* Nothing seen in a look around and a wander that covered the disc of the search's cover_mm:
 * no graspable object. */
int mg_method002_search_gives_up(const mg_task_t *t, char *why, size_t cap)
{
    if (t->graspable_seen || !t->search.covered)
        return 0;
    size_t n = mg_task_text(why, cap, 0,
                            "the search saw neither the double cross nor the red cylinder in ");
    n = mg_task_text_int(why, cap, n, t->search.cycle);
    n = mg_task_text(why, cap, n, " cycles and ");
    n = mg_task_text_int(why, cap, n, t->search.wanders);
    mg_task_text(why, cap, n, " wander legs");
    return 1;
}

void mg_method002_enter_approach_state(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    (void)now_us;
    mg_method002_enter_approach(t, in);
}

void mg_method002_approach_state(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    static const mg_frame002_t none;
    int32_t has_u, u;
    mg_method002_approach(t, now_us, in, in->frame ? (const mg_frame002_t *)in->frame : &none,
                          &has_u, &u);
}

const void *mg_method002_red_cylinder_result(const mg_task_inputs_t *in)
{
    const mg_frame002_t *f = (const mg_frame002_t *)in->frame;
    return f != NULL && f->has_rc ? &f->rc : NULL;
}

/* The pre-grasp point pregrasp_back_mm short of the axis at the grasp height. */
void mg_method002_rough_target(mg_task_t *t, const mg_task_inputs_t *in,
                               int32_t target_q4[3])
{
    mg_task_object_target_q4(t, in, t->p.grasp_height_mm, t->p.pregrasp_back_mm, target_q4);
}

/* Move in to the axis and lower. The pitch is chosen again (level first, eq. (4) of 002): the
 * pre-grasp point may only be reachable tilted, the axis often level. */
void mg_method002_enter_precise(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    int32_t target[3];
    mg_task_object_target_q4(t, in, t->p.grasp_height_mm, 0, target);
    mg_arm_pose_t pose;
    int64_t detail;
    const int32_t code = mg_method002_grasp_ik(&t->geom, target, &pose, &detail);
    if (code != MG_IK_OK) {
        char why[MG_TASK_WHY];
        const size_t n = mg_task_text(why, sizeof why, 0, "precise grasp IK: ");
        mg_task_ik_reason(&t->geom, code, detail, &pose, why, sizeof why, n);
        mg_task_fail(t, now_us, why);
        return;
    }
    mg_task_apply_pose(t, now_us, &pose, 0, 0);
    t->phase = MG_PHASE_LOWER;
}

/* the 002 cylinder's red: the red mask's rule (host/vision/red_cylinder.py red_mask) */
int mg_method002_red_paint(const int32_t rgb[3])
{
    const int32_t gb = rgb[1] > rgb[2] ? rgb[1] : rgb[2];
    const int32_t redness = rgb[0] > gb ? rgb[0] - gb : 0;
    return redness >= MG_T_RED && 2 * rgb[0] >= 5 * gb;
}

int mg_method002_held_in_view(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in)
{
    const mg_frame002_t *f = (const mg_frame002_t *)in->frame;
    return mg_task_held_fill_in_view(t, now_us, f != NULL && f->has_held_fill,
                                     f != NULL ? f->held_rgb : NULL,
                                     f != NULL ? f->held_permille : 0, mg_method002_red_paint);
}

void mg_method002_frame_of(const mg_task_t *t, const int32_t *const *words, void *frame)
{
    mg_frame002_of((mg_frame002_t *)frame, words[MG_DET_DOUBLE_CROSS], words[MG_DET_RED_CYLINDER],
                   words[MG_DET_RED_ROI], words[MG_DET_HELD_FILL], t->cam.f_px);
}
