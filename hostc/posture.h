/* Posture adjustment of the manipulator (host/posture.py), 000 section III.B.2, Fig. 4,
 * eq. (10): the waist faces the object, and the pitch change d_alpha = alpha' - alpha is shared
 * by the pitch joints, d_theta_i = d_alpha k_i theta_im / T_m, T_m = sum k_i theta_im. Angles
 * in mrad, k_theta in Q12, positions in Q4 mm. */
#ifndef MOBIGRASP_HOSTC_POSTURE_H
#define MOBIGRASP_HOSTC_POSTURE_H

#include <stdint.h>

#include "kinematics.h"

enum { MG_MARGIN_PRINTED = 0, MG_MARGIN_LIMITS = 1 };

typedef struct {
    int32_t k_theta_q12[3]; /* k_theta2..4 (000 section IV: 1, 0, 0) */
    int32_t margin_mode;    /* the margins as printed in 000, or the room to the limits */
    int32_t max_step_mrad;  /* 0: no limit per call; else |d_theta| per joint is capped */
} mg_posture_params_t;

typedef struct {
    int32_t theta2_mrad, theta3_mrad, theta4_mrad, theta5_mrad; /* new targets, in limits */
    int32_t d_theta5_mrad, d_alpha_mrad, alpha_target_mrad;
    int32_t alpha_lost_mrad; /* the part of d_alpha not applied (clamped or no margin) */
} mg_posture_adjustment_t;

void mg_margins_mrad(int32_t d_alpha_mrad, int32_t theta2_mrad, int32_t theta3_mrad,
                     int32_t theta4_mrad, int32_t mode, int32_t out[3]);
void mg_distribute_alpha(int32_t d_alpha_mrad, int32_t theta2_mrad, int32_t theta3_mrad,
                         int32_t theta4_mrad, const mg_posture_params_t *p, int32_t out[3]);
int32_t mg_desired_alpha_mrad(const mg_arm_geometry_t *g, int32_t theta2_mrad,
                              int32_t theta3_mrad, int32_t theta4_mrad,
                              const int32_t object_mm_q4[3]);
/* One step from the joints (theta2, theta3, theta4, theta5) and the object in the platform
 * frame; has_alpha_target: take alpha_target_mrad for alpha' instead. */
void mg_adjust_posture(const mg_arm_geometry_t *g, const int32_t joints_mrad[4],
                       const int32_t object_mm_q4[3], const mg_posture_params_t *p,
                       int32_t has_alpha_target, int32_t alpha_target_mrad,
                       mg_posture_adjustment_t *out);

#endif
