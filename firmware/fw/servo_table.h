/* Servo calibration of docs/conventions.md in integer form and the slewed servo bank
 * (mcu_sim/firmware/servo_table.py). Servo law and mechanical limits: protocol/joints.h; the
 * limit PARAMs may only narrow the mechanical limits.
 * Widths are Q8 us: latched (in force this period), pending (written to OCRnx), target. */
#ifndef MOBIGRASP_SERVO_TABLE_H
#define MOBIGRASP_SERVO_TABLE_H

#include <stdint.h>

#define SERVO_COUNT 6u
#define PULSE_MIN_US 500
#define PULSE_MAX_US 2500
#define GRIPPER_OPEN_US 1000

typedef struct {
    int32_t latched_q8[SERVO_COUNT];
    int32_t pending_q8[SERVO_COUNT];
    int32_t target_q8[SERVO_COUNT];
    int32_t step_q8[SERVO_COUNT];
    int16_t min_us[SERVO_COUNT];
    int16_t max_us[SERVO_COUNT];
} servo_bank_t;

int32_t mrad_to_us(uint8_t ch, int32_t value);
int32_t mrad_slew_to_us(int32_t slew_mrad_per_s);
int32_t slew_step_q8(int32_t slew_us_per_s);
void default_limits_us(uint8_t ch, int16_t *lo, int16_t *hi); /* the mechanical limits */

void servo_reset(servo_bank_t *s);
uint8_t servo_set_target_us(servo_bank_t *s, uint8_t ch, int32_t pulse_us, int32_t slew_us_per_s);
void servo_hold(servo_bank_t *s);
uint16_t servo_next_pending(servo_bank_t *s, uint8_t ch); /* the OCR value */
void servo_latch(servo_bank_t *s);
uint8_t servo_at_rest(const servo_bank_t *s, uint8_t ch);
uint16_t servo_latched_us(const servo_bank_t *s, uint8_t ch);

#endif
