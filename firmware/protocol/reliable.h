/* Receiver side of the reliable commands: the duplicate filter (protocol/reliable.py,
 * DuplicateFilter; docs/protocol.md 5.2). Two frames are the same command when they carry the
 * same seq and the same CRC-16 field. The filter keeps ``newest``, the newest seq of any valid
 * frame, and remembers the reliable commands of the last DUP_WINDOW seqs behind it: slots
 * indexed by seq % DUP_WINDOW, each a seq tag, the CRC and the answer (0xFF = empty). */
#ifndef MOBIGRASP_RELIABLE_H
#define MOBIGRASP_RELIABLE_H

#include <stdint.h>

#define DUP_WINDOW 64u /* a power of two in 2..128 */
#define DUP_EMPTY 0xFFu

enum { DUP_NEW = 0, DUP_COPY = 1, DUP_REUSED = 2 };

typedef struct {
    uint8_t tag[DUP_WINDOW];
    uint16_t crc[DUP_WINDOW];
    uint8_t result[DUP_WINDOW]; /* 0 = ACK, else the NACK reason, DUP_EMPTY = no command */
    int16_t newest;             /* -1: nothing observed since reset */
    uint32_t duplicates;
    uint32_t reused;
} dup_filter_t;

void dup_reset(dup_filter_t *d); /* forget every command and the newest seq (HELLO) */
void dup_observe(dup_filter_t *d, uint8_t seq); /* every valid frame from the peer */
uint8_t dup_classify(dup_filter_t *d, uint8_t seq, uint16_t crc); /* a reliable frame */
void dup_remember(dup_filter_t *d, uint8_t seq, uint16_t crc, uint8_t reason);
uint8_t dup_result(const dup_filter_t *d, uint8_t seq);

#endif
