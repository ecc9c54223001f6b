/* Paper 002's method (host/task/method002.py): its own state (State002) and the hooks of the
 * machine's states ported so far: the fuzzy approach's blind drive on toward the last bearing,
 * ADJUST's goal and speed, the failure reason. */
#ifndef MOBIGRASP_HOSTC_TASK_METHOD002_H
#define MOBIGRASP_HOSTC_TASK_METHOD002_H

#include <stddef.h>
#include <stdint.h>

#include "fuzzy.h"
#include "task_machine.h"

#define MG_CROSS_SPACING_MM_Q4 2080 /* the double cross's two crosses, 130 mm apart */
/* the level grasp's reach: scanned over these distances of the axis from the waist (mm,
 * step), the ends of the window kept this far inside */
#define MG_LEVEL_SCAN_LO_MM 150
#define MG_LEVEL_SCAN_HI_MM 350
#define MG_LEVEL_SCAN_STEP_MM 2
#define MG_LEVEL_MARGIN_MM 2
#define MG_RING_D_MM_Q4 232 /* 14.5 mm: the spacing D of the two rings (002 section 4) */
#define MG_WAIST_STEP_MRAD 60      /* APPROACH: the waist's turn toward e per frame */
#define MG_ADJUST_STALE_BACK_MM 40 /* ADJUST: the backstop this much nearer on an older estimate */
#define MG_SEARCH_COVER_002_MM 2500 /* SEARCH gives up once its wander has covered this disc */
/* APPROACH: a cylinder cut by the frame's border when the estimate would start ADJUST within
 * MG_BACK_OFF_WITHIN_MM beyond grasp_r_mm: back straight off MG_BACK_OFF_002_MM and look
 * again, at most MG_BACK_OFFS_002 times in a run */
#define MG_BACK_OFF_WITHIN_MM 60
#define MG_BACK_OFF_002_MM 150
#define MG_BACK_OFFS_002 2
/* APPROACH: the board alone (method002.py BOARD_ALONE_MM, BOARD_ALONE_FRAMES): this many frames
 * of the crosses this far away by their spacing without red, before any frame of the approach
 * showed red, end the run: no graspable object */
#define MG_BOARD_ALONE_MIN_MM 600
#define MG_BOARD_ALONE_MAX_MM 2000
#define MG_BOARD_ALONE_FRAMES 15
#define MG_T_RED 40 /* the red mask's redness threshold (host/vision/red_cylinder.py T_RED) */

enum { MG_STEER_NONE, MG_STEER_DOUBLE_CROSS, MG_STEER_RED_CYLINDER };

/* What 002 keeps between steps (the task's ms). */
typedef struct {
    int32_t has_fuzzy;
    mg_fuzzy_approach_t fuzzy; /* the fuzzy approach of APPROACH (002 section 2.1) */
    int32_t e_mrad;            /* the bearing e the approach steers on */
    int32_t has_prev_e;        /* (t_us, e) of the last frame that gave e */
    int64_t prev_e_t_us;
    int32_t prev_e_mrad;
    /* the blind drive on toward the marker: its odometry bearing, x_mm, y_mm, reach_mm */
    int32_t has_blind, blind[4];
    int32_t has_e_dpx, e_dpx;     /* d_pixel of the search's sighting */
    int32_t steer_on;             /* what the search found and the approach steers on */
    int32_t has_e_range, e_range_mm; /* range of the search's red ROI (its height) */
    int32_t cut;       /* the last frame showed the cylinder cut by the border (no rings) */
    int32_t back_offs; /* back-offs made in the run */
    /* the back-off under way: where it started, and the time it ended (has_ended 0: driving) */
    int32_t has_back_off, back_off_from[2], back_off_has_ended;
    int64_t back_off_ended_us;
    int32_t red_seen;     /* a frame of APPROACH showed the red cylinder (rings or ROI) */
    int32_t alone_frames; /* ... before it, frames of the crosses in MG_BOARD_ALONE_*, no red */
    int32_t look_back; /* the sonar guard drove out of R_r: turn back to the estimate */
} mg_state002_t;

void mg_method002_ms_init(void *ms);
void mg_method002_params(mg_task_params_t *p);
void mg_method002_failure_reason(const mg_task_t *t, const char *reason, char *out, size_t cap);
/* the red cylinder's colour ROI or rings in a frame of APPROACH (Method002.object_cue_seen) */
int mg_method002_object_cue_seen(const mg_task_t *t);
/* what SEARCH saw (the detectors' results as the task reads them): the double cross (its
 * midpoint's column, its crosses' spacing) or else the red cylinder's colour ROI (its column
 * and, when its box is whole, the range from its height) */
typedef struct {
    int32_t steer_on;     /* MG_STEER_DOUBLE_CROSS or MG_STEER_RED_CYLINDER (its ROI) */
    int32_t u_q4;         /* um_q4 of the double cross, u_c_q4 of the ROI */
    int32_t d_pixel_q4;   /* the double cross's */
    int32_t has_range, range_mm; /* the ROI's */
} mg_sighting002_t;
/* SEARCH found a sighting: its bearing e (002 section 2.1) kept to steer on; 1 */
int mg_method002_found(mg_task_t *t, int64_t now_us, const mg_sighting002_t *s);
/* the reason of SEARCH's transition to APPROACH, into why (cap bytes) */
void mg_method002_found_why(const mg_task_t *t, char *why, size_t cap);
/* the distances of the axis from the waist where the gripper holds it level at the grasp
 * height within the joint limits (eq. (4) of 002: theta1 + theta2 + theta3 = 0), as centre
 * and half width; 0 when there are none */
int mg_method002_grasp_reach_mm(const mg_task_t *t, int32_t *centre_mm, int32_t *half_mm);
/* the grasp's IK: the horizontal gripper of eq. (4) of 002 first, then tilted down by
 * MG_GRASP_ALPHAS_002; MG_IK_OK and *pose, or the first pitch's reason and *detail */
int32_t mg_method002_grasp_ik(const mg_arm_geometry_t *g, const int32_t target_q4[3],
                              mg_arm_pose_t *pose, int64_t *detail);
/* the grasp check's look: the fingertip (and a held cylinder with it) brought in along its
 * bearing to the first reachable of HELD_VIEWS_002 with the camera pitched down; 0: none */
int mg_method002_held_view_pose(const mg_task_t *t, mg_arm_pose_t *pose);
/* a red cylinder's result as the task reads it (host/vision/red_cylinder.py), Q4 px */
typedef struct {
    int32_t u_c_q4, v_c_q4, d_pixel_q4, width_q4;
} mg_red_cylinder_seen_t;
/* the red cylinder's axis point between its rings by 002 section 4 (the exact pinhole form of
 * mg_locate_ring_pair added to the camera point of eq. (3)); with a rolled wrist the pinhole
 * sighting (D_OC = D f / d_pixel as the depth); an mg_task_position_fn of a
 * mg_red_cylinder_seen_t */
int mg_method002_red_cylinder_position(const mg_task_t *t, const int32_t joints[6],
                                       const void *det, int32_t p_q4[3]);
/* one frame's results as APPROACH reads them */
typedef struct {
    int32_t has_frame; /* 0: no new frame */
    int32_t has_dc; /* the double cross: its midpoint, spacing and sighting */
    int32_t dc_um_q4, dc_vm_q4, dc_d_pixel_q4;
    mg_sighting_t dc_sighting;
    int32_t has_dc_sighting;
    int32_t dc_level; /* the crosses side by side (mg_double_cross_level) */
    int32_t has_rc; /* the red cylinder's rings */
    mg_red_cylinder_seen_t rc;
    int32_t has_roi; /* the red cylinder's colour ROI: its centre, box, sighting (box whole) */
    int32_t roi_u_c_q4, roi_v_c_q4;
    int32_t roi_box[4]; /* x, y, w, h px */
    int32_t has_roi_sighting;
    mg_sighting_t roi_sighting;
    int32_t has_held_fill; /* the colour filling the frame (host/vision/held_fill.py) */
    int32_t held_rgb[3], held_permille;
} mg_frame002_t;
/* APPROACH's step (002 section 2.1): the fuzzy controller on e, the waist toward what it
 * steers on; ADJUST once the cylinder is near, or placed near by the crosses; LOST when
 * nothing is seen for lost_timeout_us; *u_mrad: the fuzzy output (has_u 0: none this step) */
void mg_method002_approach(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                           const mg_frame002_t *f, int32_t *has_u, int32_t *u_mrad);
int32_t mg_method002_look_height_mm(const mg_task_params_t *p, int32_t top);
/* APPROACH's entry: a fresh fuzzy approach on the task's fuzzy parameters, the search's
 * sighting the first bearing to steer on blind */
void mg_method002_enter_approach(mg_task_t *t, const mg_task_inputs_t *in);
/* the board's distance by its crosses' spacing d_px (pinhole) */
int32_t mg_method002_board_range_mm(const mg_task_t *t, int32_t d_px);
void mg_method002_remember_bearing(mg_task_t *t, const mg_task_inputs_t *in, int32_t e_mrad,
                                   int32_t has_cue, int32_t cue_mm);
/* 1 while steering blind on the last bearing (the fuzzy approach must have started) */
int mg_method002_approach_blind(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                                int32_t *u_mrad);
/* keep what is steered on in view: the waist toward e by at most MG_WAIST_STEP_MRAD, the
 * pitch of its image row vm_q4 (has_vm 0: none) shared by eq. (10) of 000 */
void mg_method002_track_marker(mg_task_t *t, int64_t now_us, int32_t has_vm, int32_t vm_q4,
                               int32_t e_mrad);
/* the stop rule of 002 section 4, d_pixel > T_d (has_d 0: no rings measured): 1 when it
 * stopped the base and went to ROUGH_GRASP */
int mg_method002_adjust_done(mg_task_t *t, int64_t now_us, int32_t has_d, int32_t d_pixel_q4,
                             int32_t dist_mm);
/* the same on a red cylinder's result (mg_red_cylinder_seen_t; the method row's hook) */
int mg_method002_adjust_done_seen(mg_task_t *t, int64_t now_us, const void *det,
                                  int32_t dist_mm);
void mg_method002_adjust_goal_mm(const mg_task_t *t, int32_t *goal_mm, int32_t *tol_mm);
int32_t mg_method002_adjust_vmax_mmps(const mg_task_params_t *p);

/* The method row's hooks on the step's inputs (in->frame: an mg_frame002_t or NULL). */
/* SEARCH: the double cross when the frame shows it, else the red cylinder's colour ROI (an
 * mg_sighting002_t); 0: neither */
int mg_method002_search_sighting(const mg_task_t *t, const mg_task_inputs_t *in, void *sighting);
int mg_method002_found_seen(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in,
                            const void *sighting);
/* nothing seen and the rings covered: 1 and why */
int mg_method002_search_gives_up(const mg_task_t *t, char *why, size_t cap);
void mg_method002_enter_approach_state(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
void mg_method002_approach_state(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* the frame's red cylinder (an mg_red_cylinder_seen_t), NULL: none */
const void *mg_method002_red_cylinder_result(const mg_task_inputs_t *in);
void mg_method002_rough_target(mg_task_t *t, const mg_task_inputs_t *in,
                               int32_t target_q4[3]);
void mg_method002_enter_precise(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* the red of 002's cylinder: the red mask's rule */
int mg_method002_red_paint(const int32_t rgb[3]);
int mg_method002_held_in_view(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* one vision job's results (the kernels' out words by MG_DET_*, NULL: none) as 002's frame */
void mg_method002_frame_of(const mg_task_t *t, const int32_t *const *words, void *frame);

#endif
