#include "wheel_pi.h"

int32_t mmps_to_ticks_q8(int32_t mmps)
{
    int32_t v = (mmps < 0 ? -mmps : mmps) * 10430l / 1000l;
    return mmps >= 0 ? v : -v;
}

void wheel_reset(wheel_pi_t *w, int32_t count)
{
    w->target_mmps = 0;
    w->target_q8 = 0;
    w->integral = 0;
    w->last_count = count;
    w->duty = 0;
}

void wheel_set_target(wheel_pi_t *w, int16_t mmps)
{
    w->target_mmps = mmps;
    w->target_q8 = mmps_to_ticks_q8(mmps);
}

int16_t wheel_update(wheel_pi_t *w, int32_t count, int32_t kp, int32_t ki)
{
    int32_t delta = (int32_t)((uint32_t)count - (uint32_t)w->last_count);
    if (delta > WHEEL_DELTA_MAX_TICKS) {
        delta = WHEEL_DELTA_MAX_TICKS;
    } else if (delta < -WHEEL_DELTA_MAX_TICKS) {
        delta = -WHEEL_DELTA_MAX_TICKS;
    }
    int32_t measured_q8 = delta * 256;
    w->last_count = count;
    int32_t err = w->target_q8 - measured_q8;
    if (w->target_q8 == 0 && measured_q8 == 0) {
        w->integral = 0;
        w->duty = 0;
        return 0;
    }
    w->integral += err;
    if (ki > 0) {
        int32_t limit = ((int32_t)DUTY_MAX << 8) / ki;
        if (w->integral > limit) {
            w->integral = limit;
        } else if (w->integral < -limit) {
            w->integral = -limit;
        }
    } else {
        w->integral = 0;
    }
    int32_t u = kp * err + ki * w->integral;
    u = u >= 0 ? u >> 8 : -((-u + 255) >> 8); /* floor, as an arithmetic shift */
    if (u > DUTY_MAX) {
        u = DUTY_MAX;
    } else if (u < -DUTY_MAX) {
        u = -DUTY_MAX;
    }
    w->duty = (int16_t)u;
    return (int16_t)u;
}
