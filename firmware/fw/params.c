#include "params.h"

#include <string.h>

#include "../hal.h"
#include "../protocol/messages.h"
#include "servo_table.h"

typedef struct {
    uint16_t id;
    int32_t def, lo, hi;
    uint8_t writable;
} param_row_t;

/* The table lives in flash on the AVR (300 bytes of SRAM otherwise); rows are copied out by
 * row(). Servo limit defaults are the joint limits rounded inwards (servo_table.c,
 * default_limits_us); 0 here, filled in by default_of. */
static const param_row_t table[PARAM_COUNT] HAL_FLASH = {
    {P_WATCHDOG_MS, 250, 0, 10000, 1}, /* 0 disables the watchdog */
    {P_TELEMETRY_HZ, 50, 0, 100, 1},   /* 0 = telemetry off */
    {P_WHEEL_KP, 16, 0, 1000, 1},      /* Q8 duty per tick/10 ms */
    {P_WHEEL_KI, 2, 0, 1000, 1},
    {P_WHEEL_MAX_MMPS, 800, 0, 1000, 1},
    {P_SONAR_COUNT, 5, 0, 5, 1},
    {P_SONAR_SLOT_MS, 30, 20, 100, 1},
    {P_SERVO_MIN_BASE + 0, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_SERVO_MIN_BASE + 1, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_SERVO_MIN_BASE + 2, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_SERVO_MIN_BASE + 3, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_SERVO_MIN_BASE + 4, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_SERVO_MIN_BASE + 5, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_SERVO_MAX_BASE + 0, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_SERVO_MAX_BASE + 1, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_SERVO_MAX_BASE + 2, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_SERVO_MAX_BASE + 3, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_SERVO_MAX_BASE + 4, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_SERVO_MAX_BASE + 5, 0, PULSE_MIN_US, PULSE_MAX_US, 1},
    {P_FIRMWARE_VERSION, FIRMWARE_VERSION, FIRMWARE_VERSION, FIRMWARE_VERSION, 0},
};

int32_t params_values[PARAM_COUNT] FW_STATE;

static param_row_t row(uint8_t i)
{
    param_row_t r;
    hal_flash_read(&r, &table[i], sizeof r);
    return r;
}

static int32_t default_of(uint8_t i)
{
    param_row_t r = row(i);
    uint16_t id = r.id;
    int16_t lo, hi;
    if (id >= P_SERVO_MIN_BASE && id < P_SERVO_MIN_BASE + SERVO_COUNT) {
        default_limits_us((uint8_t)(id - P_SERVO_MIN_BASE), &lo, &hi);
        return lo;
    }
    if (id >= P_SERVO_MAX_BASE && id < P_SERVO_MAX_BASE + SERVO_COUNT) {
        default_limits_us((uint8_t)(id - P_SERVO_MAX_BASE), &lo, &hi);
        return hi;
    }
    return r.def;
}

void params_reset(void)
{
    for (uint8_t i = 0; i < PARAM_COUNT; i++) {
        params_values[i] = default_of(i);
    }
}

int8_t params_index(uint16_t id)
{
    for (uint8_t i = 0; i < PARAM_COUNT; i++) {
        if (row(i).id == id) {
            return (int8_t)i;
        }
    }
    return -1;
}

uint8_t params_get(uint16_t id, int32_t *value)
{
    int8_t i = params_index(id);
    if (i < 0) {
        return 0;
    }
    *value = params_values[i];
    return 1;
}

uint8_t params_check(uint16_t id, int32_t value)
{
    int8_t i = params_index(id);
    if (i < 0) {
        return NACK_BAD_PARAM;
    }
    param_row_t r = row((uint8_t)i);
    if (!r.writable) {
        return NACK_BAD_PARAM;
    }
    if (value < r.lo || value > r.hi) {
        return NACK_OUT_OF_RANGE;
    }
    int32_t other;
    if (id >= P_SERVO_MIN_BASE && id < P_SERVO_MIN_BASE + SERVO_COUNT) {
        params_get((uint16_t)(id - P_SERVO_MIN_BASE + P_SERVO_MAX_BASE), &other);
        if (value > other) {
            return NACK_OUT_OF_RANGE;
        }
    }
    if (id >= P_SERVO_MAX_BASE && id < P_SERVO_MAX_BASE + SERVO_COUNT) {
        params_get((uint16_t)(id - P_SERVO_MAX_BASE + P_SERVO_MIN_BASE), &other);
        if (value < other) {
            return NACK_OUT_OF_RANGE;
        }
    }
    return 0;
}

void params_set(uint16_t id, int32_t value)
{
    params_values[params_index(id)] = value;
}

void params_row(uint8_t i, uint16_t *id, int32_t *def, int32_t *lo, int32_t *hi, uint8_t *writable)
{
    param_row_t r = row(i);
    *id = r.id;
    *def = default_of(i);
    *lo = r.lo;
    *hi = r.hi;
    *writable = r.writable;
}
