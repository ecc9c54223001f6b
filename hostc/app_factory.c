/* The detectors' glue (host/app_factory.py, host/vision/registry.py). */
#include "app_factory.h"

#include <string.h>

#include "arm_calib.h"
#include "fixedpoint.h"
#include "json.h"
#include "ranging.h"

int mg_double_cross_level(const int32_t dc[MG_DOUBLE_CROSS_WORDS])
{
    const int64_t dv = (int64_t)dc[3] - dc[1];
    return MG_OBLIQUE_LEVEL_RATIO * (dv < 0 ? -dv : dv) <= (int64_t)dc[2] - dc[0];
}

/* the cylinder BOARD_BEHIND before the board's face along its normal, the board's plane from
 * the crosses' depth ratio Z1 : Z2 = (u2 - um) : (um - u1) (um weighted by the depths), the
 * crosses scaled 130 mm apart in the camera's level plane; 0 when the board is seen less than
 * MG_OBLIQUE_SIN_Q12 off its face, the pair is far from level (rows apart more than 1 /
 * MG_OBLIQUE_LEVEL_RATIO of the columns), its plane is not known or the place is behind the
 * camera or more than MG_OBLIQUE_AXIS_RATIO : 1 aside
 * (host/vision/double_cross.py oblique_sighting) */
static int oblique_sighting(const int32_t dc[MG_DOUBLE_CROSS_WORDS], int32_t f_px,
                            mg_sighting_t *s)
{
    const int64_t u0 = 16 * MG_U0_PX, f = 16 * (int64_t)f_px;
    const int64_t a = (int64_t)dc[2] - dc[4], b = (int64_t)dc[4] - dc[0];
    int64_t x1, z1, x2, z2, dx, dz, span, mx, mz, nx, nz, cross, cx, cz;
    if (a <= 0 || b <= 0 || !mg_double_cross_level(dc)) /* a + b = u2 - u1 */
        return 0; /* not the board's crosses side by side */
    x1 = a * (dc[0] - u0), z1 = a * f;
    x2 = b * (dc[2] - u0), z2 = b * f;
    dx = x2 - x1, dz = z2 - z1;
    span = mg_isqrt(dx * dx + dz * dz);
    if (span <= 0)
        return 0;
    mx = mg_floor_div(MG_CROSS_SPACING_MM_Q4 * (x1 + x2), 2 * span);
    mz = mg_floor_div(MG_CROSS_SPACING_MM_Q4 * (z1 + z2), 2 * span);
    nx = mg_floor_div(-dz * MG_ONE_Q12, span), nz = mg_floor_div(dx * MG_ONE_Q12, span);
    if (nx * mx + nz * mz > 0)
        nx = -nx, nz = -nz; /* the face toward the camera */
    cross = nx * mz - nz * mx;
    if ((cross < 0 ? -cross : cross) < MG_OBLIQUE_SIN_Q12 * mg_isqrt(mx * mx + mz * mz))
        return 0;
    cx = mx + mg_floor_div(MG_BOARD_BEHIND_MM_Q4 * nx, MG_ONE_Q12);
    cz = mz + mg_floor_div(MG_BOARD_BEHIND_MM_Q4 * nz, MG_ONE_Q12);
    if (cz <= 0 || (cx < 0 ? -cx : cx) > MG_OBLIQUE_AXIS_RATIO * cz)
        return 0; /* behind the camera or far aside: the frontal model */
    s->u_q4 = (int32_t)(u0 + mg_floor_div(f * cx, cz));
    s->v_q4 = dc[5];
    s->depth_mm_q4 = (int32_t)cz;
    return 1;
}

int mg_double_cross_sighting(const int32_t dc[MG_DOUBLE_CROSS_WORDS], int32_t f_px,
                             mg_sighting_t *s)
{
    /* the cylinder in front of the board: placed in its plane when it is seen obliquely,
     * else the marker centre at the board's depth spacing f / d_pixel less BOARD_BEHIND
     * (host/vision/double_cross.py sighting) */
    if (dc[6] <= 0)
        return 0;
    if (oblique_sighting(dc, f_px, s))
        return 1;
    s->u_q4 = dc[4];
    s->v_q4 = dc[5];
    s->depth_mm_q4 = (int32_t)((int64_t)MG_CROSS_SPACING_MM_Q4 * f_px * 16 / dc[6]
                               - MG_BOARD_BEHIND_MM_Q4);
    return 1;
}

int mg_red_cylinder_sighting(const int32_t rc[MG_RED_CYLINDER_WORDS], int32_t f_px,
                             mg_sighting_t *s)
{
    /* D_OC = D f / d_pixel (002 section 4) as the depth */
    if (rc[4] <= 0)
        return 0;
    s->u_q4 = rc[0];
    s->v_q4 = rc[1];
    s->depth_mm_q4 = (int32_t)((int64_t)MG_RING_D_MM_Q4 * f_px * 16 / rc[4]);
    return 1;
}

int mg_red_roi_sighting(const int32_t roi[MG_RED_ROI_WORDS], int32_t f_px, mg_sighting_t *s)
{
    /* a depth from the box's height, the cylinder's 120 mm seen h px tall; none when the box
     * meets the frame's top or bottom or is too flat to be the standing cylinder */
    const int32_t w_px = roi[4], h_px = roi[5];
    if (roi[7] || h_px <= 0 || 2 * h_px < 3 * w_px / 2)
        return 0;
    s->u_q4 = roi[0];
    s->v_q4 = roi[1];
    s->depth_mm_q4 = (int32_t)((int64_t)MG_RED_CYL_HEIGHT_MM_Q4 * f_px / h_px);
    return 1;
}

void mg_frame002_of(mg_frame002_t *f, const int32_t *dc, const int32_t *rc, const int32_t *roi,
                    const int32_t *fill, int32_t f_px)
{
    memset(f, 0, sizeof *f);
    f->has_frame = 1;
    if (dc != NULL) {
        f->has_dc = 1;
        f->dc_um_q4 = dc[4], f->dc_vm_q4 = dc[5], f->dc_d_pixel_q4 = dc[6];
        f->has_dc_sighting = mg_double_cross_sighting(dc, f_px, &f->dc_sighting);
        f->dc_level = mg_double_cross_level(dc);
    }
    if (rc != NULL) {
        f->has_rc = 1;
        f->rc.u_c_q4 = rc[0], f->rc.v_c_q4 = rc[1];
        f->rc.d_pixel_q4 = rc[4], f->rc.width_q4 = rc[5];
    }
    if (roi != NULL) {
        f->has_roi = 1;
        f->roi_u_c_q4 = roi[0], f->roi_v_c_q4 = roi[1];
        f->roi_box[0] = roi[2], f->roi_box[1] = roi[3], f->roi_box[2] = roi[4];
        f->roi_box[3] = roi[5];
        f->has_roi_sighting = mg_red_roi_sighting(roi, f_px, &f->roi_sighting);
    }
    if (fill != NULL) {
        f->has_held_fill = 1;
        f->held_rgb[0] = fill[0], f->held_rgb[1] = fill[1], f->held_rgb[2] = fill[2];
        f->held_permille = fill[3];
    }
}

void mg_frame000_of(mg_frame000_t *f, const int32_t *radial, const int32_t *plus,
                    const int32_t *spoke, const int32_t *fill, const int32_t *cut)
{
    memset(f, 0, sizeof *f);
    f->has_frame = 1;
    if (radial != NULL) { /* the symbol's centre at Y_oc (host/vision/radial_symbol.py) */
        f->has_radial = 1;
        f->radial.u_q4 = radial[0], f->radial.v_q4 = radial[1];
        f->radial.depth_mm_q4 = radial[3] * 16;
    }
    if (plus != NULL) { /* the midpoint at dist_mm (host/vision/dual_plus.py sighting) */
        f->has_plus = 1;
        f->plus.sighting.u_q4 = (int32_t)mg_floor_div((int64_t)plus[0] + plus[2], 2);
        f->plus.sighting.v_q4 = (int32_t)mg_floor_div((int64_t)plus[1] + plus[3], 2);
        f->plus.sighting.depth_mm_q4 = plus[6] * 16;
        memcpy(f->plus.uv_q4, plus, sizeof f->plus.uv_q4);
        f->plus.dist_mm = plus[6];
    }
    if (spoke != NULL) { /* atan k_T and w_T in whole px (sense.py spoke_reading) */
        f->has_spoke = 1;
        f->spoke_angle_mrad = spoke[3];
        f->spoke_width_px = (int32_t)mg_floor_div((int64_t)spoke[4] + 8, 16);
    }
    if (fill != NULL) {
        f->has_held_fill = 1;
        f->held_rgb[0] = fill[0], f->held_rgb[1] = fill[1], f->held_rgb[2] = fill[2];
        f->held_permille = fill[3];
    }
    if (cut != NULL) { /* the symbol cut by the border: the side it is cut at */
        f->has_cut = 1;
        f->cut_side = cut[4];
        f->cut_low_px = cut[1] + cut[3];
        f->cut_w_px = cut[2], f->cut_h_px = cut[3];
    }
}

/* an object of int members (keys sorted by the caller), int arrays and arrays of pairs */
typedef struct {
    const char *key;
    int32_t at, n; /* words at .. at + n of the result: n 1 an int, else an array */
    int32_t is_bool;
    int32_t pairs; /* an array of words[at - 1] [a, b] pairs from words[at] on (n unused) */
} member_t;

static size_t object_json(const int32_t *words, const member_t *m, int32_t n_members, char *out,
                          size_t cap)
{
    mg_json_t j;
    mg_json_init(&j, out, cap > 0 ? cap - 1 : 0);
    mg_json_begin_object(&j);
    for (int32_t i = 0; i < n_members; i++) {
        mg_json_key(&j, m[i].key);
        if (m[i].is_bool) {
            mg_json_bool(&j, words[m[i].at] != 0);
        } else if (m[i].pairs) {
            mg_json_begin_array(&j);
            for (int32_t k = 0; k < words[m[i].at - 1]; k++) {
                mg_json_int_pair(&j, words[m[i].at + 2 * k], words[m[i].at + 2 * k + 1]);
            }
            mg_json_end_array(&j);
        } else if (m[i].n == 1) {
            mg_json_int(&j, words[m[i].at]);
        } else {
            mg_json_begin_array(&j);
            for (int32_t k = 0; k < m[i].n; k++)
                mg_json_int(&j, words[m[i].at + k]);
            mg_json_end_array(&j);
        }
    }
    mg_json_end_object(&j);
    if (j.overflow || cap == 0)
        return 0;
    out[j.len] = 0;
    return j.len;
}

size_t mg_double_cross_json(const int32_t dc[MG_DOUBLE_CROSS_WORDS], char *out, size_t cap)
{
    static const member_t m[] = {{"d_pixel_q4", 6, 1, 0, 0}, {"e_mrad", 7, 1, 0, 0},
                                 {"u1_q4", 0, 1, 0, 0},      {"u2_q4", 2, 1, 0, 0},
                                 {"um_q4", 4, 1, 0, 0},      {"v1_q4", 1, 1, 0, 0},
                                 {"v2_q4", 3, 1, 0, 0},      {"vm_q4", 5, 1, 0, 0},
                                 {"votes", 8, 2, 0, 0}};
    return object_json(dc, m, (int32_t)(sizeof m / sizeof m[0]), out, cap);
}

size_t mg_red_cylinder_json(const int32_t rc[MG_RED_CYLINDER_WORDS], char *out, size_t cap)
{
    static const member_t m[] = {{"d_pixel_q4", 4, 1, 0, 0}, {"ring1_v_q4", 2, 1, 0, 0},
                                 {"ring2_v_q4", 3, 1, 0, 0}, {"roi", 6, 4, 0, 0},
                                 {"u_c_q4", 0, 1, 0, 0},     {"v_c_q4", 1, 1, 0, 0},
                                 {"width_q4", 5, 1, 0, 0}};
    return object_json(rc, m, (int32_t)(sizeof m / sizeof m[0]), out, cap);
}

size_t mg_radial_cut_json(const int32_t rc[MG_RADIAL_CUT_WORDS], char *out, size_t cap)
{
    static const member_t m[] = {{"h", 3, 1, 0, 0}, {"side", 4, 1, 0, 0}, {"w", 2, 1, 0, 0},
                                 {"x", 0, 1, 0, 0}, {"y", 1, 1, 0, 0}};
    return object_json(rc, m, (int32_t)(sizeof m / sizeof m[0]), out, cap);
}

size_t mg_red_roi_json(const int32_t roi[MG_RED_ROI_WORDS], char *out, size_t cap)
{
    static const member_t m[] = {{"area_px", 6, 1, 0, 0}, {"roi", 2, 4, 0, 0},
                                 {"touches_edge", 7, 1, 1, 0}, {"u_c_q4", 0, 1, 0, 0},
                                 {"v_c_q4", 1, 1, 0, 0}};
    return object_json(roi, m, (int32_t)(sizeof m / sizeof m[0]), out, cap);
}

size_t mg_held_fill_json(const int32_t fill[MG_HELD_FILL_WORDS], char *out, size_t cap)
{
    static const member_t m[] = {{"fill_permille", 3, 1, 0, 0}, {"rgb", 0, 3, 0, 0}};
    return object_json(fill, m, (int32_t)(sizeof m / sizeof m[0]), out, cap);
}

size_t mg_radial_symbol_json(const int32_t rs[MG_RADIAL_SYMBOL_WORDS], char *out, size_t cap)
{
    static const member_t m[] = {{"diameter_q4", 2, 1, 0, 0}, {"u_q4", 0, 1, 0, 0},
                                 {"v_q4", 1, 1, 0, 0},        {"x_oc_mm", 4, 1, 0, 0},
                                 {"y_oc_mm", 3, 1, 0, 0},     {"z_oc_mm", 5, 1, 0, 0}};
    return object_json(rs, m, (int32_t)(sizeof m / sizeof m[0]), out, cap);
}

size_t mg_dual_plus_json(const int32_t dp[MG_DUAL_PLUS_WORDS], char *out, size_t cap)
{
    static const member_t m[] = {{"d_eff_q4", 5, 1, 0, 0}, {"d_pixel_q4", 4, 1, 0, 0},
                                 {"dist_mm", 6, 1, 0, 0},  {"dist_raw_mm", 7, 1, 0, 0},
                                 {"u1_q4", 0, 1, 0, 0},    {"u2_q4", 2, 1, 0, 0},
                                 {"v1_q4", 1, 1, 0, 0},    {"v2_q4", 3, 1, 0, 0},
                                 {"x_oc_mm", 8, 1, 0, 0},  {"y_oc_mm", 9, 1, 0, 0},
                                 {"z_oc_mm", 10, 1, 0, 0}};
    return object_json(dp, m, (int32_t)(sizeof m / sizeof m[0]), out, cap);
}

size_t mg_spoke_json(const int32_t sp[MG_SPOKE_WORDS], char *out, size_t cap)
{
    static const member_t m[] = {{"angle_mrad", 3, 1, 0, 0}, {"points_q4", 6, 0, 0, 1},
                                 {"slope_q12", 2, 1, 0, 0},  {"u_c_q4", 0, 1, 0, 0},
                                 {"v_c_q4", 1, 1, 0, 0},     {"width_q4", 4, 1, 0, 0}};
    if (sp[5] < 0 || sp[5] > (MG_SPOKE_WORDS - 6) / 2)
        return 0;
    return object_json(sp, m, (int32_t)(sizeof m / sizeof m[0]), out, cap);
}

void mg_input_builder_init(mg_input_builder_t *b)
{
    memset(b, 0, sizeof *b);
    mg_odometry_init(&b->odometry, 0, 0, 0);
    b->pose = mg_odometry_pose(&b->odometry);
}

void mg_input_builder_step(mg_input_builder_t *b, const mg_host_link_t *link, int64_t now_us,
                           const void *frame, mg_task_inputs_t *in)
{
    const mg_telemetry_t *tel = link->has_telemetry ? &link->telemetry : NULL;
    if (link->mcu_resets != b->resets_seen) { /* counters and clock restarted at 0 */
        b->resets_seen = link->mcu_resets;
        mg_odometry_resync(&b->odometry);
    }
    if (tel != NULL && link->counters.telemetry != b->telemetry_seen) {
        b->telemetry_seen = link->counters.telemetry;
        b->pose = mg_odometry_update(&b->odometry, tel->time_us, tel->enc_left, tel->enc_right);
    }
    memset(in, 0, sizeof *in);
    if (tel != NULL) {
        int32_t pulses[MG_N_CHANNELS];
        for (int32_t ch = 0; ch < MG_N_CHANNELS; ch++)
            pulses[ch] = tel->servo_us[ch];
        in->has_joints = mg_pulses_to_joints_mrad(pulses, in->joints_mrad);
        in->n_sonar = MSG_SONAR_COUNT < MG_TASK_SONARS ? MSG_SONAR_COUNT : MG_TASK_SONARS;
        for (int32_t k = 0; k < in->n_sonar; k++)
            in->sonar_mm[k] = tel->sonar_mm[k];
    }
    in->x_mm = (int32_t)mg_div_round64(b->pose.x_um, 1000);
    in->y_mm = (int32_t)mg_div_round64(b->pose.y_um, 1000);
    in->heading_mrad = b->pose.heading_mrad;
    in->v_mmps = b->pose.speed_mm_s;
    const int flag = tel != NULL && (tel->flags & FLAG_GRIPPER_CLOSED);
    if (!flag) {
        b->has_closed_since = 0;
    } else if (!b->has_closed_since) {
        b->has_closed_since = 1;
        b->closed_since_us = now_us;
    }
    in->grasp_closed = flag && now_us - b->closed_since_us >= MG_GRIPPER_CLOSE_US;
    in->frame = frame;
}
