/* Duplicate filter: a ring of (seq, time, answer) in arrival order. */
#include "reliable.h"

void dup_reset(dup_filter_t *d)
{
    d->head = 0;
    d->count = 0;
}

static int8_t find(const dup_filter_t *d, uint8_t seq)
{
    for (uint8_t k = 0; k < d->count; k++) {
        uint8_t i = (uint8_t)((d->head + k) % DUP_WINDOW);
        if (d->seq[i] == seq) {
            return (int8_t)i;
        }
    }
    return -1;
}

uint8_t dup_is_new(dup_filter_t *d, uint8_t seq, uint32_t now_us)
{
    while (d->count && (uint32_t)(now_us - d->t_us[d->head]) >= DUP_EXPIRY_US) {
        d->head = (uint8_t)((d->head + 1u) % DUP_WINDOW);
        d->count--;
    }
    if (find(d, seq) >= 0) {
        d->duplicates++;
        return 0;
    }
    if (d->count >= DUP_WINDOW) {
        if ((uint32_t)(now_us - d->t_us[d->head]) < DUP_EXPIRY_US) {
            d->live_evictions++;
        }
        d->head = (uint8_t)((d->head + 1u) % DUP_WINDOW);
        d->count--;
    }
    uint8_t i = (uint8_t)((d->head + d->count) % DUP_WINDOW);
    d->seq[i] = seq;
    d->t_us[i] = now_us;
    d->result[i] = 0;
    d->count++;
    return 1;
}

void dup_set_result(dup_filter_t *d, uint8_t seq, uint8_t reason)
{
    int8_t i = find(d, seq);
    if (i >= 0) {
        d->result[i] = reason;
    }
}

uint8_t dup_result(const dup_filter_t *d, uint8_t seq)
{
    int8_t i = find(d, seq);
    return i < 0 ? 0 : d->result[i];
}
