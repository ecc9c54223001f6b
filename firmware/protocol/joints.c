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

static const joint_t joints[JOINT_COUNT] JOINTS_ATTR = {
    {1000, 1, 0, 1000},     /* gripper: closure per mille, 1000 us = open */
    {1500, 1, -1571, 1571}, /* wrist roll */
    {2455, 1, -3000, 0},    /* wrist pitch */
    {2455, 1, -2800, 0},    /* elbow pitch */
    {545, 1, 0, 3000},      /* shoulder pitch */
    {1500, 1, -1400, 1400}, /* waist yaw */
};

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

static int32_t floor_div(int32_t num, int32_t den)
{
    int32_t q = num / den;
    return (num % den != 0 && num < 0) ? q - 1 : q;
}

void joint_mech_limits_us(uint8_t ch, int16_t *lo, int16_t *hi)
{
    joint_t j = joint_row(ch);
    int32_t lo_us, hi_us;
    if (ch == JOINT_GRIPPER_CH) {
        int32_t a = j.pulse0_us + j.lo, b = j.pulse0_us + j.hi;
        lo_us = a < b ? a : b;
        hi_us = a < b ? b : a;
    } else {
        int32_t base = (int32_t)j.pulse0_us * (int32_t)JOINT_K_DEN;
        int32_t a = base + j.direction * (int32_t)j.lo * (int32_t)JOINT_K_NUM;
        int32_t b = base + j.direction * (int32_t)j.hi * (int32_t)JOINT_K_NUM;
        int32_t e0 = a < b ? a : b, e1 = a < b ? b : a;
        lo_us = -floor_div(-e0, (int32_t)JOINT_K_DEN); /* ceil: inwards */
        hi_us = floor_div(e1, (int32_t)JOINT_K_DEN);   /* floor: inwards */
    }
    *lo = (int16_t)(lo_us < JOINT_PULSE_MIN_US ? JOINT_PULSE_MIN_US : lo_us);
    *hi = (int16_t)(hi_us > JOINT_PULSE_MAX_US ? JOINT_PULSE_MAX_US : hi_us);
}
