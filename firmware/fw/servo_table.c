#include "servo_table.h"

#define K_NUM 20000l /* us per mrad = K_NUM / K_DEN = 2000 / (1000 pi) */
#define K_DEN 31416l
#define PERIODS_PER_S 50l

/* (pulse at 0 rad or 0 per mille, direction, joint lower, upper limit): conventions.md */
static const int16_t joint_table[SERVO_COUNT][4] = {
    {GRIPPER_OPEN_US, 1, 0, 1000},
    {1500, 1, -1571, 1571},
    {2455, 1, -3000, 0},
    {2455, 1, -2800, 0},
    {545, 1, 0, 3000},
    {1500, 1, -1400, 1400},
};
static const int16_t home_us[SERVO_COUNT] = {GRIPPER_OPEN_US, 1500, 1500, 1500, 1500, 1500};

static int32_t div_round(int32_t num, int32_t den) /* halves away from zero, den > 0 */
{
    return num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
}

static int32_t floor_div(int32_t num, int32_t den)
{
    int32_t q = num / den;
    return (num % den != 0 && num < 0) ? q - 1 : q;
}

int32_t mrad_to_us(uint8_t ch, int32_t value)
{
    if (ch == 0) {
        return joint_table[0][0] + value;
    }
    return joint_table[ch][0] + joint_table[ch][1] * div_round(value * K_NUM, K_DEN);
}

void default_limits_us(uint8_t ch, int16_t *lo, int16_t *hi)
{
    const int16_t *j = joint_table[ch];
    if (ch == 0) {
        *lo = (int16_t)(j[0] + j[2]);
        *hi = (int16_t)(j[0] + j[3]);
        return;
    }
    int32_t base = (int32_t)j[0] * K_DEN;
    int32_t a = base + (int32_t)j[1] * j[2] * K_NUM;
    int32_t b = base + (int32_t)j[1] * j[3] * K_NUM;
    int32_t e0 = a < b ? a : b;
    int32_t e1 = a < b ? b : a;
    int32_t lo_us = -floor_div(-e0, K_DEN); /* ceil */
    int32_t hi_us = floor_div(e1, K_DEN);
    *lo = (int16_t)(lo_us < PULSE_MIN_US ? PULSE_MIN_US : lo_us);
    *hi = (int16_t)(hi_us > PULSE_MAX_US ? PULSE_MAX_US : hi_us);
}

int32_t slew_step_q8(int32_t slew_us_per_s)
{
    if (slew_us_per_s <= 0) {
        return 0;
    }
    int32_t step = (slew_us_per_s << 8) / PERIODS_PER_S;
    return step > 1 ? step : 1;
}

int32_t mrad_slew_to_us(int32_t slew_mrad_per_s)
{
    if (slew_mrad_per_s <= 0) {
        return 0;
    }
    int32_t us = div_round(slew_mrad_per_s * K_NUM, K_DEN);
    return us > 1 ? us : 1;
}

void servo_reset(servo_bank_t *s)
{
    for (uint8_t ch = 0; ch < SERVO_COUNT; ch++) {
        default_limits_us(ch, &s->min_us[ch], &s->max_us[ch]);
        int32_t home = (int32_t)home_us[ch] << 8;
        s->latched_q8[ch] = s->pending_q8[ch] = s->target_q8[ch] = home;
        s->step_q8[ch] = 0;
    }
}

uint8_t servo_set_target_us(servo_bank_t *s, uint8_t ch, int32_t pulse_us, int32_t slew_us_per_s)
{
    int32_t clamped = pulse_us < s->min_us[ch] ? s->min_us[ch] : pulse_us;
    if (clamped > s->max_us[ch]) {
        clamped = s->max_us[ch];
    }
    s->target_q8[ch] = clamped << 8;
    s->step_q8[ch] = slew_step_q8(slew_us_per_s);
    return clamped != pulse_us;
}

void servo_hold(servo_bank_t *s)
{
    for (uint8_t ch = 0; ch < SERVO_COUNT; ch++) {
        s->target_q8[ch] = s->latched_q8[ch];
    }
}

uint16_t servo_next_pending(servo_bank_t *s, uint8_t ch)
{
    int32_t latched = s->latched_q8[ch];
    int32_t delta = s->target_q8[ch] - latched;
    int32_t step = s->step_q8[ch];
    if (step && delta > step) {
        delta = step;
    } else if (step && delta < -step) {
        delta = -step;
    }
    int32_t value = latched + delta;
    int32_t lo = (int32_t)s->min_us[ch] << 8;
    int32_t hi = (int32_t)s->max_us[ch] << 8;
    value = value < lo ? lo : value > hi ? hi : value;
    s->pending_q8[ch] = value;
    return (uint16_t)(((value + 64) >> 7) - 1); /* 0.5 us ticks minus one */
}

void servo_latch(servo_bank_t *s)
{
    for (uint8_t ch = 0; ch < SERVO_COUNT; ch++) {
        s->latched_q8[ch] = s->pending_q8[ch];
    }
}

uint8_t servo_at_rest(const servo_bank_t *s, uint8_t ch)
{
    return s->target_q8[ch] == s->latched_q8[ch];
}

uint16_t servo_latched_us(const servo_bank_t *s, uint8_t ch)
{
    return (uint16_t)((s->latched_q8[ch] + 128) >> 8);
}
