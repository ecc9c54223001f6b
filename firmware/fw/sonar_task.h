/* Sequential polling of up to five sonars, one per slot (mcu_sim/firmware/sonar_task.py):
 * range d_mm = width_us * 343 / 2000; no falling edge, or beyond 2.5 m, gives NO_ECHO. */
#ifndef MOBIGRASP_SONAR_TASK_H
#define MOBIGRASP_SONAR_TASK_H

#include <stdint.h>

#define SONARS_MAX 5u
#define SONAR_NO_ECHO 0xFFFFu
#define SONAR_MAX_RANGE_MM 2500u

typedef struct {
    uint16_t range_mm[SONARS_MAX];
    uint8_t index;
    volatile uint32_t rise_us; /* stamped by the echo ISR */
    volatile uint32_t fall_us;
    volatile uint8_t have_rise;
    volatile uint8_t have_fall;
    uint32_t next_slot_us;
    volatile uint8_t active;
} sonar_task_t;

void sonar_reset(sonar_task_t *s, uint32_t now_us);
void sonar_on_echo(sonar_task_t *s, uint8_t index, uint8_t level, uint32_t t_us); /* ISR */
void sonar_end_slot(sonar_task_t *s);
/* Next sonar to trigger, or -1 when none is fitted; schedules the end of the slot. */
int8_t sonar_start_slot(sonar_task_t *s, uint8_t count, uint32_t now_us, uint32_t slot_us);

#endif
