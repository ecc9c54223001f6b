/* Wheel speed PI on encoder counts at 100 Hz, integer only (mcu_sim/firmware/wheel_pi.py):
 * target mm/s -> ticks per 10 ms in Q8 (x 10.430: 40 mm wheel, 1024 counts/rev),
 * duty = (kp e + ki sum e) >> 8 clamped to +-255, the integral clamped so ki x integral alone
 * cannot exceed full duty. */
#ifndef MOBIGRASP_WHEEL_PI_H
#define MOBIGRASP_WHEEL_PI_H

#include <stdint.h>

#define CONTROL_PERIOD_US 10000ul
#define DUTY_MAX 255
/* Ticks counted in one period are clamped to this before the Q8 shift, so kp (<= 1000) times
 * the error stays inside an int32 whatever the encoder does (over 60 revolutions per 10 ms:
 * the duty saturates either way). */
#define WHEEL_DELTA_MAX_TICKS 8191l

typedef struct {
    int16_t target_mmps;
    int32_t target_q8;
    int32_t integral;
    int32_t last_count;
    int16_t duty;
} wheel_pi_t;

int32_t mmps_to_ticks_q8(int32_t mmps);
void wheel_reset(wheel_pi_t *w, int32_t count);
void wheel_set_target(wheel_pi_t *w, int16_t mmps);
int16_t wheel_update(wheel_pi_t *w, int32_t count, int32_t kp, int32_t ki);

#endif
