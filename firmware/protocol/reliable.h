/* Receiver side of the reliable commands: the duplicate filter (protocol/reliable.py,
 * DuplicateFilter). Remembers the last DUP_WINDOW executed seqs and the answer given to each
 * for DUP_EXPIRY_US, oldest first in a ring. */
#ifndef MOBIGRASP_RELIABLE_H
#define MOBIGRASP_RELIABLE_H

#include <stdint.h>

#define DUP_WINDOW 16u
#define DUP_EXPIRY_US 250000ul

typedef struct {
    uint8_t seq[DUP_WINDOW];
    uint8_t result[DUP_WINDOW]; /* 0 = ACK, else the NACK reason */
    uint32_t t_us[DUP_WINDOW];
    uint8_t head; /* oldest entry */
    uint8_t count;
    uint32_t duplicates;
    uint32_t live_evictions; /* pushed out before expiry: a copy would run twice */
} dup_filter_t;

void dup_reset(dup_filter_t *d); /* forget every seq (HELLO); counters kept */
uint8_t dup_is_new(dup_filter_t *d, uint8_t seq, uint32_t now_us);
void dup_set_result(dup_filter_t *d, uint8_t seq, uint8_t reason);
uint8_t dup_result(const dup_filter_t *d, uint8_t seq);

#endif
