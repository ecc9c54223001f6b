/* Wheel odometry from cumulative encoder ticks (host/odometry.py). */
#include "odometry.h"

#include "fixedpoint.h"

#define TICKS_PER_REV 1024
#define TRACK_UM 300000
/* um of travel per tick in Q16: round(2 pi 40000 / 1024 * 65536) */
#define UM_PER_TICK_Q16 16084954LL
#define URAD_PER_TURN 6283185
#define MAX_WHEEL_SPEED_MM_S 1500 /* faster than any command (SetWheels is limited to 1000) */

int64_t mg_wrap_urad(int64_t a_urad)
{
    return mg_floor_mod(a_urad + URAD_PER_TURN / 2, URAD_PER_TURN) - URAD_PER_TURN / 2;
}

void mg_odometry_reset(mg_odometry_t *o, int64_t x_um, int64_t y_um, int32_t heading_mrad)
{
    o->x_acc = x_um * 8192;
    o->y_acc = y_um * 8192;
    o->theta0_urad = (int64_t)heading_mrad * 1000;
    o->ticks_l = o->ticks_r = 0;
    o->raw_l = o->raw_r = 0;
    o->t_us = 0;
    o->has_sample = 0;
    o->s_l_um = o->s_r_um = 0;
    o->speed_mm_s = o->yaw_rate_mrad_s = 0;
}

void mg_odometry_init(mg_odometry_t *o, int64_t x_um, int64_t y_um, int32_t heading_mrad)
{
    mg_odometry_reset(o, x_um, y_um, heading_mrad);
    o->dropped = 0;
}

static int64_t heading_urad(const mg_odometry_t *o, int64_t s_l_um, int64_t s_r_um)
{
    return o->theta0_urad + mg_div_round64((s_r_um - s_l_um) * 1000000, TRACK_UM);
}

int64_t mg_odometry_heading_urad(const mg_odometry_t *o)
{
    return heading_urad(o, o->s_l_um, o->s_r_um);
}

void mg_odometry_resync(mg_odometry_t *o)
{
    const int64_t x_acc = o->x_acc, y_acc = o->y_acc, h = mg_odometry_heading_urad(o);
    mg_odometry_reset(o, 0, 0, 0); /* leaves the dropped count alone */
    o->x_acc = x_acc, o->y_acc = y_acc, o->theta0_urad = h;
}

static mg_pose_t pose_at(const mg_odometry_t *o, int64_t h_urad)
{
    mg_pose_t p;
    p.x_um = (o->x_acc + 4096) >> 13;
    p.y_um = (o->y_acc + 4096) >> 13;
    p.heading_mrad = (int32_t)mg_div_round64(mg_wrap_urad(h_urad), 1000);
    p.speed_mm_s = o->speed_mm_s;
    p.yaw_rate_mrad_s = o->yaw_rate_mrad_s;
    return p;
}

mg_pose_t mg_odometry_pose(const mg_odometry_t *o)
{
    return pose_at(o, mg_odometry_heading_urad(o));
}

/* the counter difference unwrapped modulo 2^32 */
static int64_t wrap32(int32_t now, int32_t before)
{
    return (int32_t)((uint32_t)now - (uint32_t)before);
}

mg_pose_t mg_odometry_update(mg_odometry_t *o, int64_t t_us, int32_t enc_left,
                             int32_t enc_right)
{
    if (!o->has_sample) {
        o->raw_l = enc_left, o->raw_r = enc_right, o->t_us = t_us, o->has_sample = 1;
        return mg_odometry_pose(o);
    }
    const int64_t dt_us = t_us - o->t_us;
    if (dt_us < 0) { /* telemetry from the past: ignored entirely */
        o->dropped++;
        return mg_odometry_pose(o);
    }
    const int64_t dl = wrap32(enc_left, o->raw_l), dr = wrap32(enc_right, o->raw_r);
    o->raw_l = enc_left, o->raw_r = enc_right, o->t_us = t_us;
    /* the ticks a wheel at MAX_WHEEL_SPEED_MM_S could make in dt, and 4 ticks of slack */
    const int64_t limit = MAX_WHEEL_SPEED_MM_S * dt_us * TICKS_PER_REV / 251327000 + 4;
    if (dl > limit || -dl > limit || dr > limit || -dr > limit) {
        o->dropped++; /* used only to re-synchronise the counters */
        return mg_odometry_pose(o);
    }
    const int64_t theta_prev = heading_urad(o, o->s_l_um, o->s_r_um);
    o->ticks_l += dl;
    o->ticks_r += dr;
    const int64_t s_l = (o->ticks_l * UM_PER_TICK_Q16 + (1 << 15)) >> 16;
    const int64_t s_r = (o->ticks_r * UM_PER_TICK_Q16 + (1 << 15)) >> 16;
    const int64_t d_sum = (s_l - o->s_l_um) + (s_r - o->s_r_um); /* twice the centre's travel */
    o->s_l_um = s_l, o->s_r_um = s_r;
    const int64_t theta = heading_urad(o, s_l, s_r);
    const int32_t mid_mrad = (int32_t)mg_div_round64(theta_prev + theta, 2000);
    o->x_acc += d_sum * mg_cos_q12(mid_mrad);
    o->y_acc += d_sum * mg_sin_q12(mid_mrad);
    if (dt_us > 0) {
        o->speed_mm_s = (int32_t)mg_div_round64(d_sum * 500, dt_us);
        o->yaw_rate_mrad_s = (int32_t)mg_div_round64((theta - theta_prev) * 1000, dt_us);
    }
    return pose_at(o, theta);
}

mg_ops_t mg_odometry_update_ops(void)
{
    const mg_ops_t ops = {0, 0, 40, 6, 0, 8, 3, 4, 0, 0, 0};
    return ops;
}
