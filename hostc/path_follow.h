/* Following a planned Bezier curve in time (host/control/path_follow.py): the curve's integer
 * reference table, the feed-forward of eq. (8) of 000 (v_l = v - w l_w / 2, v_r = v + w l_w / 2
 * with w counter-clockwise, i.e. 000's w_w = -w) and the integer tracking law of Kanayama et al.
 * (1990) on the odometry error: v = v_r cos e_th + K_x e_x, w = w_r + v_r (K_y e_y + K_th sin
 * e_th). Errors in mm, angles in mrad, sine and cosine Q12. */
#ifndef MOBIGRASP_HOSTC_PATH_FOLLOW_H
#define MOBIGRASP_HOSTC_PATH_FOLLOW_H

#include <stdint.h>

#include "budget.h"
#include "odometry.h"

#define MG_WHEEL_LIMIT_MM_S 1000
#define MG_TRAJ_MAX_SAMPLES 256

/* The reference of one curve, sampled at plan time; times relative to the curve's start. */
typedef struct {
    int32_t n; /* 2..MG_TRAJ_MAX_SAMPLES */
    int32_t t_us[MG_TRAJ_MAX_SAMPLES];
    int32_t x_um[MG_TRAJ_MAX_SAMPLES], y_um[MG_TRAJ_MAX_SAMPLES];
    int32_t heading_mrad[MG_TRAJ_MAX_SAMPLES];
    int32_t v_mm_s[MG_TRAJ_MAX_SAMPLES];
    int32_t w_mrad_s[MG_TRAJ_MAX_SAMPLES]; /* counter-clockwise yaw rate v kappa */
} mg_trajectory_t;

typedef struct {
    int32_t x_um, y_um, heading_mrad, v_mm_s, w_mrad_s, index;
} mg_traj_ref_t;

typedef struct {
    int32_t k_x_q12;       /* 1/s in Q12 */
    int32_t k_y_per_m2;    /* 1/m^2 */
    int32_t k_theta_per_m; /* 1/m */
} mg_follow_gains_t;

typedef struct {
    int32_t left_mm_s, right_mm_s;
    int32_t done;     /* the end reached (or the overtime passed) */
    int32_t error_mm; /* distance from the reference point (the larger axis) */
} mg_wheel_command_t;

typedef struct {
    const mg_trajectory_t *traj;
    int64_t start_us;
    int32_t v_limit_mm_s, goal_tol_mm;
    int64_t overtime_us;
    mg_follow_gains_t gains;
    int32_t hint; /* the segment of the last step */
    int32_t steps;
} mg_path_follower_t;

/* the reference of one curve (control points in 1/16 mm and 1/16 ms, 4 rows x, y, t) at n
 * samples tau_j = (j << 15) / (n - 1) (path_follow.py reference_q): 0, or -1 (out->n = 0)
 * when n is not in 2..MG_TRAJ_MAX_SAMPLES, a coordinate is 2^21 counts or more, t_tau <= 0
 * or |P_tau| = 0 at a sample, or a speed reaches 64 m/s */
int mg_trajectory_from_ctrl(const int32_t *ctrl, int32_t n, mg_trajectory_t *out);
/* its ARM920T cost (Trajectory.ops) */
mg_ops_t mg_trajectory_ops(int32_t n);
int32_t mg_wrap_mrad(int64_t a_mrad); /* to [-3142, 3141], 2 pi = 6283 mrad */
/* the reference at t_us (linear between samples), searched from the segment hint */
mg_traj_ref_t mg_trajectory_at(const mg_trajectory_t *traj, int64_t t_us, int32_t hint);
/* eq. (8) of 000 with w counter-clockwise, scaled into +-limit keeping the turn */
void mg_wheel_speeds(int32_t v_mm_s, int32_t w_mrad_s, int32_t limit_mm_s, int32_t *left,
                     int32_t *right);
void mg_path_follower_init(mg_path_follower_t *f, const mg_trajectory_t *traj, int64_t start_us,
                           int32_t v_limit_mm_s, const mg_follow_gains_t *gains,
                           int32_t goal_tol_mm, int64_t overtime_us);
mg_wheel_command_t mg_path_follower_step(mg_path_follower_t *f, int64_t t_us,
                                         const mg_pose_t *pose);
mg_ops_t mg_path_follow_step_ops(void);

#endif
