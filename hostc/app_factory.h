/* The detectors' glue of the host program (host/app_factory.py, host/vision/registry.py): the
 * vision kernels' out words (kernels.h, held_fill.h) as the task reads them (002's frame,
 * mg_frame002_t), their sightings (the target's pixel and depth, mg_sighting_t: the
 * registry's sighting functions) and their results' JSON for the trace's detect event (as
 * host/app.py's jsonable gives the result dataclasses, keys sorted). */
#ifndef MOBIGRASP_HOSTC_APP_FACTORY_H
#define MOBIGRASP_HOSTC_APP_FACTORY_H

#include <stddef.h>
#include <stdint.h>

#include "app_link.h"
#include "odometry.h"
#include "task_method000.h"
#include "task_method002.h"

/* telemetry to the task's inputs (host/app_factory.py InputBuilder): odometry integrates the
 * encoder counts of every new telemetry frame, the joints come from the measured pulse widths
 * through the joint table, a sonar without echo (0xFFFF) is passed on as is; the gripper is
 * reported closed once the MCU's flag has been up MG_GRIPPER_CLOSE_US (the servo's swing) */
#define MG_GRIPPER_CLOSE_US 450000
typedef struct {
    mg_odometry_t odometry;
    mg_pose_t pose;
    uint32_t telemetry_seen; /* the link's telemetry count at the last update */
    int32_t resets_seen;
    int32_t has_closed_since;
    int64_t closed_since_us;
} mg_input_builder_t;

void mg_input_builder_init(mg_input_builder_t *b);
/* the inputs of the task step at now_us (frame: the step's results, NULL: no new frame) */
void mg_input_builder_step(mg_input_builder_t *b, const mg_host_link_t *link, int64_t now_us,
                           const void *frame, mg_task_inputs_t *in);

#define MG_BOARD_BEHIND_MM_Q4 2400   /* the cylinder stands this far before the board */
/* the board seen at least this far off its face (sine, Q12: 30 degrees): the cylinder placed in
 * its plane (host/vision/double_cross.py OBLIQUE_SIN_Q12) */
#define MG_OBLIQUE_SIN_Q12 2048
#define MG_OBLIQUE_AXIS_RATIO 4 /* ... and the place at most atan 4 off the camera's axis */
#define MG_OBLIQUE_LEVEL_RATIO 4 /* ... and the crosses' rows within 1/4 of their columns */
#define MG_RED_CYL_HEIGHT_MM_Q4 1920 /* 120 mm: the cylinder's height (docs/markers.md) */

/* the out words of each kernel: mg_double_cross (u1, v1, u2, v2, um, vm, d_pixel, e, votes1,
 * votes2), mg_red_cylinder (u_c, v_c, ring1_v, ring2_v, d_pixel, width, roi x, y, w, h),
 * mg_red_roi (u_c, v_c, roi x, y, w, h, area_px, touches_edge), mg_held_fill (r, g, b,
 * permille) */
#define MG_DOUBLE_CROSS_WORDS 10
#define MG_RED_CYLINDER_WORDS 10
#define MG_RED_ROI_WORDS 8
#define MG_HELD_FILL_WORDS 4
/* the 000 kernels' (kernels.h): mg_radial_symbol (u, v, diameter, y_oc, x_oc, z_oc),
 * mg_dual_plus (u1, v1, u2, v2, d_pixel, d_eff, dist, dist_raw, x_oc, y_oc, z_oc), mg_spoke
 * (u_c, v_c, slope, angle, width, n_points, then n_points (u, v) pairs, at most 10) */
#define MG_RADIAL_SYMBOL_WORDS 6
#define MG_RADIAL_CUT_WORDS 5 /* mg_radial_cut: x, y, w, h, side */
#define MG_DUAL_PLUS_WORDS 11
#define MG_SPOKE_WORDS 26

/* the sightings (registry sighting functions): 1 and s, or 0 (no target) */
int mg_double_cross_sighting(const int32_t dc[MG_DOUBLE_CROSS_WORDS], int32_t f_px,
                             mg_sighting_t *s);
int mg_red_cylinder_sighting(const int32_t rc[MG_RED_CYLINDER_WORDS], int32_t f_px,
                             mg_sighting_t *s);
int mg_red_roi_sighting(const int32_t roi[MG_RED_ROI_WORDS], int32_t f_px, mg_sighting_t *s);

/* 000's (and 001's) frame of one vision job's results (NULL: the detector found nothing or
 * did not run): the radial symbol's sighting (its centre at the depth Y_oc), the dual "+"
 * (its midpoint at the depth dist_mm, both "+"), the spoke's angle and width, the colour
 * filling the frame */
void mg_frame000_of(mg_frame000_t *f, const int32_t *radial, const int32_t *plus,
                    const int32_t *spoke, const int32_t *fill, const int32_t *cut);

/* 002's frame of one vision job's results (NULL: the detector found nothing or did not run);
 * f_px: the camera's */
void mg_frame002_of(mg_frame002_t *f, const int32_t *dc, const int32_t *rc, const int32_t *roi,
                    const int32_t *fill, int32_t f_px);

/* a result's JSON (NULL-terminated in out, cap bytes): its length, 0 when it did not fit */
size_t mg_double_cross_json(const int32_t dc[MG_DOUBLE_CROSS_WORDS], char *out, size_t cap);
size_t mg_red_cylinder_json(const int32_t rc[MG_RED_CYLINDER_WORDS], char *out, size_t cap);
size_t mg_red_roi_json(const int32_t roi[MG_RED_ROI_WORDS], char *out, size_t cap);
size_t mg_held_fill_json(const int32_t fill[MG_HELD_FILL_WORDS], char *out, size_t cap);
size_t mg_radial_symbol_json(const int32_t rs[MG_RADIAL_SYMBOL_WORDS], char *out, size_t cap);
size_t mg_radial_cut_json(const int32_t rc[MG_RADIAL_CUT_WORDS], char *out, size_t cap);
size_t mg_dual_plus_json(const int32_t dp[MG_DUAL_PLUS_WORDS], char *out, size_t cap);
size_t mg_spoke_json(const int32_t sp[MG_SPOKE_WORDS], char *out, size_t cap);

#endif
