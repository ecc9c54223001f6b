/* Monocular ranging of papers 000 and 002 from a known physical size, in integers
 * (host/ranging.py, whose docstring maps 002's printed signs to docs/conventions.md). The exact
 * ring-pair geometry the 002 task uses, mg_locate_ring_pair, is declared with the vision
 * kernels (kernels.h); the rest is here. Millimetres, camera-centred, platform-aligned axes
 * (X right, Y forward, Z up); pixel quantities Q4. */
#ifndef MOBIGRASP_HOSTC_RANGING_H
#define MOBIGRASP_HOSTC_RANGING_H

#include <stdint.h>

#include "budget.h"

#define MG_D_RING_UM 14500 /* 002 section 5: D = 1.45 cm between the rings */
#define MG_F_PX_002 350
#define MG_U0_PX 160
#define MG_V0_PX 120

/* the pinhole range size f / size_px in mm (size in um, pixel size in Q4): 1, or 0 when the
 * pixel size is not > 0 */
int mg_range_from_size_mm(int32_t size_um, int32_t f_px, int32_t size_px_q4, int32_t *out_mm);

/* 002 section 4 as printed (with conventions.md signs): D_OC, theta_v, theta_h and the point;
 * for comparison only (the task uses mg_locate_ring_pair) */
typedef struct {
    int32_t d_oc_mm, theta_v_mrad, theta_h_mrad, x_oc_mm, y_oc_mm, z_oc_mm;
} mg_range_002_t;
int mg_range_002(int32_t d_pixel_q4, int32_t u_c_q4, int32_t v_c_q4, int32_t alpha_mrad,
                 int32_t theta5_mrad, int32_t f_px, int32_t u0_px, int32_t v0_px, int32_t d_um,
                 mg_range_002_t *out);
mg_ops_t mg_range_002_ops(void);
mg_ops_t mg_locate_ring_pair_ops(void);

/* the bearing of a target from the platform origin (right positive), from its bearing and
 * horizontal distance seen from the camera at (cam_x, cam_y): 002's e with the parallax of a
 * camera ahead of the waist */
int32_t mg_platform_bearing_mrad(int32_t cam_x_mm, int32_t cam_y_mm, int32_t bearing_mrad,
                                 int32_t dist_mm);

#endif
