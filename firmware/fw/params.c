#include "params.h"

#include <string.h>

#include "../hal.h"
#include "../protocol/messages.h"
#include "servo_table.h"

typedef struct {
    uint16_t id;
    int32_t def, lo, hi;
    uint8_t writable;
    uint8_t safety; /* range is the compile-time bound; HELLO restores the power-on value */
} param_row_t;

/* In flash on the AVR (row() copies a row out). The servo limit rows' default and range are
 * the channel's mechanical limits (protocol/joints.c), filled in by row(): a PARAM may only
 * narrow them. */
static const param_row_t table[PARAM_COUNT] HAL_FLASH = {
    {P_WATCHDOG_MS, 250, WATCHDOG_MIN_MS, WATCHDOG_MAX_MS, 1, 1},
    {P_TELEMETRY_HZ, 50, 0, 100, 1, 0}, /* 0 = telemetry off */
    {P_WHEEL_KP, 16, 0, 1000, 1, 0},    /* Q8 duty per tick/10 ms */
    {P_WHEEL_KI, 2, 0, 1000, 1, 0},
    {P_WHEEL_MAX_MMPS, 800, 0, 1000, 1, 1},
    {P_SONAR_COUNT, 5, 0, 5, 1, 0},
    {P_SONAR_SLOT_MS, 30, 20, 100, 1, 0},
    {P_SERVO_MIN_BASE + 0, 0, 0, 0, 1, 1},
    {P_SERVO_MIN_BASE + 1, 0, 0, 0, 1, 1},
    {P_SERVO_MIN_BASE + 2, 0, 0, 0, 1, 1},
    {P_SERVO_MIN_BASE + 3, 0, 0, 0, 1, 1},
    {P_SERVO_MIN_BASE + 4, 0, 0, 0, 1, 1},
    {P_SERVO_MIN_BASE + 5, 0, 0, 0, 1, 1},
    {P_SERVO_MAX_BASE + 0, 0, 0, 0, 1, 1},
    {P_SERVO_MAX_BASE + 1, 0, 0, 0, 1, 1},
    {P_SERVO_MAX_BASE + 2, 0, 0, 0, 1, 1},
    {P_SERVO_MAX_BASE + 3, 0, 0, 0, 1, 1},
    {P_SERVO_MAX_BASE + 4, 0, 0, 0, 1, 1},
    {P_SERVO_MAX_BASE + 5, 0, 0, 0, 1, 1},
    {P_FIRMWARE_VERSION, FIRMWARE_VERSION, FIRMWARE_VERSION, FIRMWARE_VERSION, 0, 0},
};

int32_t params_values[PARAM_COUNT] FW_STATE;

static param_row_t row(uint8_t i)
{
    param_row_t r;
    hal_flash_read(&r, &table[i], sizeof r);
    uint8_t is_min = r.id >= P_SERVO_MIN_BASE && r.id < P_SERVO_MIN_BASE + SERVO_COUNT;
    uint8_t is_max = r.id >= P_SERVO_MAX_BASE && r.id < P_SERVO_MAX_BASE + SERVO_COUNT;
    if (is_min || is_max) {
        int16_t lo, hi;
        default_limits_us((uint8_t)(r.id - (is_min ? P_SERVO_MIN_BASE : P_SERVO_MAX_BASE)), &lo, &hi);
        r.lo = lo;
        r.hi = hi;
        r.def = is_min ? lo : hi;
    }
    return r;
}

/* The value at start-up: the table's, or a build-time choice (hal_boot_param). */
static int32_t power_on(uint8_t i)
{
    param_row_t r = row(i);
    int32_t v = r.def;
    hal_boot_param(r.id, &v);
    return v;
}

void params_reset(void)
{
    for (uint8_t i = 0; i < PARAM_COUNT; i++) {
        params_values[i] = power_on(i);
    }
}

uint8_t params_restore_safety(void)
{
    uint8_t servo_changed = 0;
    for (uint8_t i = 0; i < PARAM_COUNT; i++) {
        param_row_t r = row(i);
        if (!r.safety) {
            continue;
        }
        int32_t v = power_on(i);
        if (params_values[i] != v) {
            params_values[i] = v;
            if (r.id >= P_SERVO_MIN_BASE) {
                servo_changed = 1;
            }
        }
    }
    return servo_changed;
}

int8_t params_index(uint16_t id)
{
    /* the id alone: row() also works out a servo row's limits, two 32-bit divisions */
    for (uint8_t i = 0; i < PARAM_COUNT; i++) {
        uint16_t row_id;
        hal_flash_read(&row_id, &table[i].id, sizeof row_id);
        if (row_id == id) {
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
        return r.safety ? NACK_BAD_PARAM : NACK_OUT_OF_RANGE;
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

void params_row(uint8_t i, uint16_t *id, int32_t *def, int32_t *lo, int32_t *hi, uint8_t *writable,
                uint8_t *safety)
{
    param_row_t r = row(i);
    *id = r.id;
    *def = r.def;
    *lo = r.lo;
    *hi = r.hi;
    *writable = r.writable;
    *safety = r.safety;
}
