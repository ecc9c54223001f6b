/* The PARAM table (mcu_sim/firmware/params.py; docs/firmware.md lists it): ids, defaults and
 * ranges in flash, one int32 value per row in SRAM. Safety PARAMs (watchdog, wheel speed limit,
 * servo limits) cannot be widened over the wire: their range is the compile-time bound (a value
 * outside it is NACKed BAD_PARAM) and a HELLO puts them back to their power-on values. */
#ifndef MOBIGRASP_PARAMS_H
#define MOBIGRASP_PARAMS_H

#include <stdint.h>

#define FIRMWARE_VERSION 1
#define P_WATCHDOG_MS 1u
#define P_TELEMETRY_HZ 2u
#define P_WHEEL_KP 3u
#define P_WHEEL_KI 4u
#define P_WHEEL_MAX_MMPS 5u
#define P_SONAR_COUNT 6u
#define P_SONAR_SLOT_MS 7u
#define P_SERVO_MIN_BASE 16u
#define P_SERVO_MAX_BASE 24u
#define P_FIRMWARE_VERSION 100u
#define PARAM_COUNT 20u
#define WATCHDOG_MIN_MS 50
#define WATCHDOG_MAX_MS 1000

/* rows of params_values the main loop reads directly */
enum {
    I_WATCHDOG_MS = 0, I_TELEMETRY_HZ = 1, I_WHEEL_KP = 2, I_WHEEL_KI = 3, I_WHEEL_MAX_MMPS = 4,
    I_SONAR_COUNT = 5, I_SONAR_SLOT_MS = 6
};

extern int32_t params_values[PARAM_COUNT];

void params_reset(void);                /* power-on values */
uint8_t params_restore_safety(void);    /* HELLO: safety PARAMs to power-on; 1 if a servo limit changed */
int8_t params_index(uint16_t id);               /* -1 if unknown */
uint8_t params_get(uint16_t id, int32_t *value); /* 0 if unknown */
uint8_t params_check(uint16_t id, int32_t value); /* 0, NACK_BAD_PARAM or NACK_OUT_OF_RANGE */
void params_set(uint16_t id, int32_t value);    /* a value params_check accepted */
/* Row ``i`` of the table (for the tests that compare it with params.py). */
void params_row(uint8_t i, uint16_t *id, int32_t *def, int32_t *lo, int32_t *hi, uint8_t *writable,
                uint8_t *safety);

#endif
