#include "joints.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#define JOINTS_ATTR PROGMEM
#define JOINTS_READ(dst, src) memcpy_P((dst), (src), sizeof(joint_t))
#else
#include <string.h>
#define JOINTS_ATTR
#define JOINTS_READ(dst, src) memcpy((dst), (src), sizeof(joint_t))
#endif

/* The rows (pulse0_us, direction, lo, hi), each given to GRIPPER or SERVO: the table and the
 * mechanical limits below are both made from them. */
#define JOINT_ROWS(GRIPPER, SERVO)                                                          \
    GRIPPER(1000, 1, 0, 1000)   /* gripper: closure per mille, 1000 us = open */            \
    SERVO(1500, 1, -1571, 1571) /* wrist roll */                                            \
    SERVO(2455, 1, -3000, 0)    /* wrist pitch */                                           \
    SERVO(2455, 1, -2800, 0)    /* elbow pitch */                                           \
    SERVO(545, 1, 0, 3000)      /* shoulder pitch */                                        \
    SERVO(1500, 1, -1400, 1400) /* waist yaw */

#define JOINT_AS_ROW(p0, dir, lo, hi) {p0, dir, lo, hi},
static const joint_t joints[JOINT_COUNT] JOINTS_ATTR = {JOINT_ROWS(JOINT_AS_ROW, JOINT_AS_ROW)};

/* Mechanical limits in us (docs/conventions.md): the joint limits through the pulse law,
 * rounded inwards (ceil at the low end, floor at the high end) and clamped to 500..2500 us.
 * Integer constant expressions, so the compiler works them out: the AVR does no 32-bit
 * division for them at start-up. The ends are pulse0 * K_DEN + dir * limit * K_NUM. */
#define J_MIN(a, b) ((a) < (b) ? (a) : (b))
#define J_MAX(a, b) ((a) < (b) ? (b) : (a))
#define J_FLOOR_DIV(n, d) ((n) >= 0 ? (n) / (d) : -((-(n) + (d) - 1) / (d)))
#define J_END(p0, dir, t) \
    ((int32_t)(p0) * (int32_t)JOINT_K_DEN + (int32_t)(dir) * (int32_t)(t) * (int32_t)JOINT_K_NUM)
#define J_SERVO_LIMITS(p0, dir, lo, hi)                                                      \
    {J_MAX(JOINT_PULSE_MIN_US,                                                              \
           -J_FLOOR_DIV(-J_MIN(J_END(p0, dir, lo), J_END(p0, dir, hi)), (int32_t)JOINT_K_DEN)), \
     J_MIN(JOINT_PULSE_MAX_US,                                                              \
           J_FLOOR_DIV(J_MAX(J_END(p0, dir, lo), J_END(p0, dir, hi)), (int32_t)JOINT_K_DEN))},
#define J_GRIPPER_LIMITS(p0, dir, lo, hi)                                                    \
    {J_MAX(JOINT_PULSE_MIN_US, J_MIN((p0) + (lo), (p0) + (hi))),                           \
     J_MIN(JOINT_PULSE_MAX_US, J_MAX((p0) + (lo), (p0) + (hi)))},
static const int16_t mech_limits_us[JOINT_COUNT][2] JOINTS_ATTR = {
    JOINT_ROWS(J_GRIPPER_LIMITS, J_SERVO_LIMITS)};

joint_t joint_row(uint8_t ch)
{
    joint_t j;
    JOINTS_READ(&j, &joints[ch]);
    return j;
}

uint32_t joint_div_round_u(uint32_t num, uint32_t den)
{
    return (num + den / 2u) / den; /* = floor((2 num + den) / (2 den)) for an even den */
}

int32_t joint_pulse_us(uint8_t ch, int32_t value)
{
    joint_t j = joint_row(ch);
    if (ch == JOINT_GRIPPER_CH) {
        return j.pulse0_us + value;
    }
    int32_t mag = (int32_t)joint_div_round_u((uint32_t)(value < 0 ? -value : value) * JOINT_K_NUM,
                                             JOINT_K_DEN);
    return j.pulse0_us + j.direction * (value < 0 ? -mag : mag);
}

void joint_mech_limits_us(uint8_t ch, int16_t *lo, int16_t *hi)
{
    int16_t both[2];
#ifdef __AVR__
    memcpy_P(both, mech_limits_us[ch], sizeof both);
#else
    memcpy(both, mech_limits_us[ch], sizeof both);
#endif
    *lo = both[0];
    *hi = both[1];
}
