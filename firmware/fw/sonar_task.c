#include "sonar_task.h"

#include "../hal.h"

void sonar_reset(sonar_task_t *s, uint32_t now_us)
{
    for (uint8_t i = 0; i < SONARS_MAX; i++) {
        s->range_mm[i] = SONAR_NO_ECHO;
    }
    s->index = SONARS_MAX - 1u; /* so the first slot polls sonar 0 */
    s->have_rise = s->have_fall = 0;
    s->active = 0;
    s->next_slot_us = now_us;
}

void sonar_on_echo(sonar_task_t *s, uint8_t index, uint8_t level, uint32_t t_us)
{
    if (!s->active || index != s->index) {
        return;
    }
    if (level) {
        s->rise_us = t_us;
        s->have_rise = 1;
    } else if (s->have_rise) {
        s->fall_us = t_us;
        s->have_fall = 1;
    }
}

void sonar_end_slot(sonar_task_t *s)
{
    if (!s->active) {
        return;
    }
    /* only the echo handler's stamps are read with interrupts off: once the slot is closed
     * the handler leaves them alone, and the 32-bit division (some 600 cycles on the AVR)
     * runs with interrupts on, within the interrupts-off budget of docs/firmware.md */
    uint8_t irq = hal_irq_save();
    uint8_t heard = s->have_rise && s->have_fall;
    uint32_t width_us = s->fall_us - s->rise_us;
    s->active = 0;
    hal_irq_restore(irq);
    uint16_t mm = SONAR_NO_ECHO;
    if (heard) {
        uint32_t d = width_us * 343u / 2000u;
        if (d <= SONAR_MAX_RANGE_MM) {
            mm = (uint16_t)d;
        }
    }
    s->range_mm[s->index] = mm;
}

int8_t sonar_start_slot(sonar_task_t *s, uint8_t count, uint32_t now_us, uint32_t slot_us)
{
    s->next_slot_us = now_us + slot_us;
    for (uint8_t i = count; i < SONARS_MAX; i++) {
        s->range_mm[i] = SONAR_NO_ECHO;
    }
    if (count == 0) {
        return -1;
    }
    uint8_t next = s->index < count ? (uint8_t)((s->index + 1u) % count) : 0;
    uint8_t irq = hal_irq_save();
    s->index = next;
    s->have_rise = s->have_fall = 0;
    s->active = 1;
    hal_irq_restore(irq);
    return (int8_t)s->index;
}
