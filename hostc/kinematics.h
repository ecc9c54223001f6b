/* Arm forward and inverse kinematics in fixed point (host/kinematics.py): eq. (3) and (11) of
 * 000, eq. (4) of 002. Numbering as docs/conventions.md (paper 000): theta4 shoulder, theta3
 * elbow, theta2 wrist pitch, theta5 waist yaw; alpha = theta2 + theta3 + theta4 the pitch of
 * the last link. Angles in integer mrad, lengths and points in Q4 mm (1/16 mm). */
#ifndef MOBIGRASP_HOSTC_KINEMATICS_H
#define MOBIGRASP_HOSTC_KINEMATICS_H

#include <stdint.h>

#define MG_ALPHA_DOWN_MRAD (-1571) /* alpha_T = -pi/2: gripper vertical, looking down (000) */
#define MG_ROLL_PRECISE_MRAD 1571 /* theta1 rolls by pi/2 once the gripper is above the object */
#define MG_QUARTER_TURN_MRAD 1571 /* a "+" repeats every quarter turn */
#define MG_ALPHA_LEVEL_MRAD 0      /* horizontal gripper (002) */
#define MG_REACH_TOL_MM_Q4 8       /* 0.5 mm: rounding slack at the workspace boundary */
#define MG_LIMIT_SNAP_MRAD 30      /* theta3..5 this close outside a limit are put on it */
#define MG_ALPHA_SNAP_MRAD 30      /* theta2 too: alpha within 30 mrad of alpha_T */

typedef struct {
    int32_t l1_mm_q4, l2_mm_q4, l3_mm_q4; /* shoulder, elbow, wrist to camera/gripper point */
} mg_arm_geometry_t;

typedef struct {
    int32_t theta2_mrad, theta3_mrad, theta4_mrad, theta5_mrad;
} mg_arm_pose_t;

/* Why a target cannot be reached (host/kinematics.py Unreachable's reasons); *detail: the
 * channel for MG_IK_JOINT_LIMIT (and *pose the pose outside the limits), the distance in Q4 mm
 * for the others. */
enum {
    MG_IK_OK = 0,
    MG_IK_ON_AXIS = 1,     /* target on the waist axis: waist angle undefined */
    MG_IK_OUT_OF_REACH = 2, /* wrist point farther than l1 + l2 */
    MG_IK_TOO_CLOSE = 3,   /* wrist point nearer than |l1 - l2| */
    MG_IK_JOINT_LIMIT = 4, /* a joint would leave its limits */
    MG_IK_MISSES = 5       /* at the limits the point misses the target by more than 1 mm */
};

/* Camera/gripper point (P_crx, P_cry, P_crz) in Q4 mm, eq. (3) of 000. */
void mg_fk_mm_q4(const mg_arm_geometry_t *g, int32_t theta2_mrad, int32_t theta3_mrad,
                 int32_t theta4_mrad, int32_t theta5_mrad, int32_t out_mm_q4[3]);
/* Eq. (11) of 000 with l3 pitched at alpha_T (any alpha_T; 002's eq. (4) at alpha_T = 0):
 * MG_IK_OK and *pose (within the joint limits), or a reason and *detail. Targets within
 * 2^24 Q4 mm (1 km) of the waist. */
int32_t mg_ik_pitch_mm_q4(const mg_arm_geometry_t *g, const int32_t target_mm_q4[3],
                          int32_t alpha_t_mrad, mg_arm_pose_t *pose, int64_t *detail);

/* 000 section III.C.2: the image angle of a spoke of slope k_T (Q12) in mrad, and one step of
 * the precise grasp (roll to pi/2, k_T to 0 with theta5, w_T within [w_min, w_max]). */
int32_t mg_spoke_angle_mrad(int32_t slope_q12);
typedef struct {
    int32_t slope_tol_mrad, max_step_mrad, yaw_sign, dz_step_mm, w_min_px, w_max_px;
} mg_precise_params_t;
typedef struct {
    int32_t theta1_mrad, theta5_mrad, dz_mm, aligned, d_align_mrad;
    int32_t slope_ok;   /* |spoke angle| within the tolerance */
    int32_t angle_mrad; /* the spoke angle folded into a quarter turn */
} mg_precise_step_t;
void mg_precise_grasp_step(int32_t theta5_mrad, int32_t spoke_mrad, int32_t width_px,
                           const mg_precise_params_t *p, mg_precise_step_t *out);

#endif
