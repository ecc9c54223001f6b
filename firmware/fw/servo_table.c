#include "servo_table.h"

#include "../protocol/joints.h"

#define PERIODS_PER_S 50l

static const int16_t home_us[SERVO_COUNT] = {GRIPPER_OPEN_US, 1500, 1500, 1500, 1500, 1500};

int32_t mrad_to_us(uint8_t ch, int32_t value) { return joint_pulse_us(ch, value); }

void default_limits_us(uint8_t ch, int16_t *lo, int16_t *hi) { joint_mech_limits_us(ch, lo, hi); }

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
    /* up to 65535 x 33215: beyond an int32, inside a uint32 */
    int32_t us = (int32_t)joint_div_round_u((uint32_t)slew_mrad_per_s * JOINT_K_NUM, JOINT_K_DEN);
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
