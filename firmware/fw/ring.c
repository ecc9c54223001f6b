#include "ring.h"

void ring_clear(byte_ring_t *r)
{
    r->head = 0;
    r->tail = 0;
}

uint8_t ring_put(byte_ring_t *r, uint8_t byte)
{
    uint8_t next = (uint8_t)((r->head + 1u) % RX_RING_BYTES);
    if (next == r->tail) {
        r->overruns++;
        return 0;
    }
    r->buf[r->head] = byte;
    r->head = next;
    return 1;
}

uint8_t ring_get(byte_ring_t *r)
{
    uint8_t byte = r->buf[r->tail];
    r->tail = (uint8_t)((r->tail + 1u) % RX_RING_BYTES);
    return byte;
}
