/* Integer wheel odometry of the differential-drive base from cumulative encoder ticks
 * (host/odometry.py, whose docstring gives the model): wheel travel from the cumulative ticks,
 * the heading from the cumulative travel difference over the track, the position integrated
 * with the midpoint heading of each update. 1024 ticks a revolution, wheel radius 40 mm, track
 * 300 mm; world x east, y north, heading counter-clockwise from +x. */
#ifndef MOBIGRASP_HOSTC_ODOMETRY_H
#define MOBIGRASP_HOSTC_ODOMETRY_H

#include <stdint.h>

#include "budget.h"

typedef struct {
    int64_t x_um, y_um;
    int32_t heading_mrad; /* wrapped to [-3142, 3141] */
    int32_t speed_mm_s, yaw_rate_mrad_s;
} mg_pose_t;

typedef struct {
    int64_t x_acc, y_acc; /* position in um * 2^13: the Q12 product of a sum of two travels */
    int64_t theta0_urad;
    int64_t ticks_l, ticks_r; /* unwrapped cumulative ticks since reset */
    int32_t raw_l, raw_r;     /* the last counters as received */
    int64_t t_us;
    int32_t has_sample;       /* 0: the next update only takes the reference */
    int64_t s_l_um, s_r_um;
    int32_t speed_mm_s, yaw_rate_mrad_s;
    int32_t dropped;          /* updates refused (from the past, or an impossible jump) */
} mg_odometry_t;

void mg_odometry_init(mg_odometry_t *o, int64_t x_um, int64_t y_um, int32_t heading_mrad);
void mg_odometry_reset(mg_odometry_t *o, int64_t x_um, int64_t y_um, int32_t heading_mrad);
/* the MCU restarted its clock and counters: keep the pose, take the next sample as reference */
void mg_odometry_resync(mg_odometry_t *o);
int64_t mg_odometry_heading_urad(const mg_odometry_t *o); /* not wrapped */
mg_pose_t mg_odometry_pose(const mg_odometry_t *o);
mg_pose_t mg_odometry_update(mg_odometry_t *o, int64_t t_us, int32_t enc_left,
                             int32_t enc_right);
int64_t mg_wrap_urad(int64_t a_urad); /* to [-pi, pi) */
mg_ops_t mg_odometry_update_ops(void);

#endif
