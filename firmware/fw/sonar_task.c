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
    uint8_t irq = hal_irq_save();
    uint16_t mm = SONAR_NO_ECHO;
    if (s->have_rise && s->have_fall) {
        uint32_t width_us = s->fall_us - s->rise_us;
        uint32_t d = width_us * 343u / 2000u;
        if (d <= SONAR_MAX_RANGE_MM) {
            mm = (uint16_t)d;
        }
    }
    s->range_mm[s->index] = mm;
    s->active = 0;
    hal_irq_restore(irq);
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
    uint8_t irq = hal_irq_save();
    s->index = s->index < count ? (uint8_t)((s->index + 1u) % count) : 0;
    s->have_rise = s->have_fall = 0;
    s->active = 1;
    hal_irq_restore(irq);
    return (int8_t)s->index;
}
