/* The arm's joint table (protocol/joints.py, docs/conventions.md): pulse law and mechanical
 * limits, integers only. pulse = pulse0 + dir * theta_mrad * K_NUM / K_DEN rounded, with
 * K_NUM / K_DEN = 33215 / 52174 us per mrad (2/pi correctly rounded for every int16 angle);
 * channel 0 is the gripper, 1 us per per mille of closure. */
#ifndef MOBIGRASP_JOINTS_H
#define MOBIGRASP_JOINTS_H

#include <stdint.h>

#define JOINT_COUNT 6u
#define JOINT_PULSE_MIN_US 500
#define JOINT_PULSE_MAX_US 2500
#define JOINT_K_NUM 33215ul
#define JOINT_K_DEN 52174ul
#define JOINT_GRIPPER_CH 0u

typedef struct {
    int16_t pulse0_us;
    int8_t direction;
    int16_t lo, hi; /* mrad; per mille for the gripper */
} joint_t;

joint_t joint_row(uint8_t ch);
/* |num| / den rounded half away from zero, in unsigned 32-bit arithmetic (den even). */
uint32_t joint_div_round_u(uint32_t num, uint32_t den);
int32_t joint_pulse_us(uint8_t ch, int32_t value); /* not clamped */
void joint_mech_limits_us(uint8_t ch, int16_t *lo, int16_t *hi);

#endif
