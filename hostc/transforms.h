/* Camera -> platform transform of paper 000, eqs. (1)-(3), in fixed point (host/transforms.py,
 * whose docstring maps the printed equations): R_c^r = Rz(-theta5) Rx(alpha) C for OpenCV camera
 * axes (C: x -> X right, z -> Y forward, y -> -Z), P_or = R_c^r P_oc + P_cr. Lengths in mm,
 * angles in mrad, rotations Q12; the wrist roll theta1 is taken as 0. */
#ifndef MOBIGRASP_HOSTC_TRANSFORMS_H
#define MOBIGRASP_HOSTC_TRANSFORMS_H

#include <stdint.h>

#include "budget.h"
#include "fixedpoint.h"
#include "kinematics.h"

/* paper camera axes (X left, Y optical axis, Z up) -> OpenCV axes (x right, y down, z) */
void mg_paper_cam_to_cv(const int32_t p_paper[3], int32_t out_cv[3]);
void mg_r_c_r_q12(int32_t alpha_mrad, int32_t theta5_mrad, mg_mat_q12 out); /* eq. (1) */
/* P_cr of eq. (3) in whole mm */
void mg_camera_position_mm(const mg_arm_geometry_t *g, int32_t theta2_mrad,
                           int32_t theta3_mrad, int32_t theta4_mrad, int32_t theta5_mrad,
                           int32_t out_mm[3]);
/* eq. (2): a point in OpenCV camera axes (mm) -> the platform frame (mm) */
void mg_camera_to_platform_mm(const int32_t p_cv_mm[3], const mg_arm_geometry_t *g,
                              int32_t theta2_mrad, int32_t theta3_mrad, int32_t theta4_mrad,
                              int32_t theta5_mrad, int32_t out_mm[3]);
/* 002's X_OR = X_OC + X_CR (section 4): a camera-centred offset in platform axes plus P_cr */
void mg_platform_offset_to_platform_mm(const int32_t offset_mm[3], const mg_arm_geometry_t *g,
                                       int32_t theta2_mrad, int32_t theta3_mrad,
                                       int32_t theta4_mrad, int32_t theta5_mrad,
                                       int32_t out_mm[3]);
/* eq. (2) with the joints read from the six telemetry pulses: 1, or 0 for a pulse out of
 * 500..2500 us */
int mg_camera_to_platform_from_servo_us(const int32_t p_cv_mm[3], const mg_arm_geometry_t *g,
                                        const int32_t servo_us[6], int32_t out_mm[3]);
mg_ops_t mg_camera_to_platform_ops(void);

#endif
