/* Duplicate filter: slots by seq, cleared as ``newest`` passes them (one lap of the 8-bit seq). */
#include "reliable.h"

#define DUP_MASK (DUP_WINDOW - 1u)
#define DUP_AHEAD_MAX (256u - DUP_WINDOW)

void dup_reset(dup_filter_t *d)
{
    d->newest = -1;
    for (uint8_t i = 0; i < DUP_WINDOW; i++) {
        d->result[i] = DUP_EMPTY;
    }
}

void dup_observe(dup_filter_t *d, uint8_t seq)
{
    if (d->newest < 0) {
        d->newest = seq;
        return;
    }
    uint8_t newest = (uint8_t)d->newest;
    uint8_t ahead = (uint8_t)(seq - newest);
    if (ahead >= 1u && ahead <= DUP_AHEAD_MAX) {
        uint8_t n = ahead < DUP_WINDOW ? ahead : (uint8_t)DUP_WINDOW;
        for (uint8_t k = 1; k <= n; k++) {
            d->result[(uint8_t)(newest + k) & DUP_MASK] = DUP_EMPTY;
        }
        d->newest = seq;
    }
}

uint8_t dup_classify(dup_filter_t *d, uint8_t seq, uint16_t crc)
{
    uint8_t i = seq & DUP_MASK;
    if (d->result[i] == DUP_EMPTY || d->tag[i] != seq) {
        return DUP_NEW;
    }
    if (d->crc[i] == crc) {
        d->duplicates++;
        return DUP_COPY;
    }
    d->reused++;
    return DUP_REUSED;
}

void dup_remember(dup_filter_t *d, uint8_t seq, uint16_t crc, uint8_t reason)
{
    uint8_t i = seq & DUP_MASK;
    d->tag[i] = seq;
    d->crc[i] = crc;
    d->result[i] = reason;
}

uint8_t dup_result(const dup_filter_t *d, uint8_t seq)
{
    uint8_t i = seq & DUP_MASK;
    uint8_t r = d->result[i];
    return (r == DUP_EMPTY || d->tag[i] != seq) ? 0 : r;
}
