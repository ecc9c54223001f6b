/* Byte ring shared by an ISR (producer) and the main loop (mcu_sim/firmware/ring.py).
 * One slot stays free to tell full from empty: a ring of RING_BYTES holds RING_BYTES - 1. */
#ifndef MOBIGRASP_RING_H
#define MOBIGRASP_RING_H

#include <stdint.h>

#define RX_RING_BYTES 128u

typedef struct {
    uint8_t buf[RX_RING_BYTES];
    volatile uint8_t head; /* next write (ISR) */
    volatile uint8_t tail; /* next read (main loop) */
    uint32_t overruns;
} byte_ring_t;

void ring_clear(byte_ring_t *r);
uint8_t ring_put(byte_ring_t *r, uint8_t byte); /* ISR side; 0 and overruns + 1 when full */
static inline uint8_t ring_empty(const byte_ring_t *r) { return r->head == r->tail; }
uint8_t ring_get(byte_ring_t *r); /* main-loop side; the ring must not be empty */

#endif
