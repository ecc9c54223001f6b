/* The sender's side of the reliable commands (protocol/reliable.py SequenceCounter and
 * RetransmitQueue; docs/protocol.md): every reliable frame is resent with the same wire bytes
 * (same seq) every timeout_us until its ACK/NACK, at most max_retries times, then reported as
 * failed. The firmware has the receiver's side (firmware/protocol/reliable.h). Slots are kept in
 * the order they were tracked, as the Python dict keeps them. */
#ifndef MOBIGRASP_HOSTC_RETRANSMIT_H
#define MOBIGRASP_HOSTC_RETRANSMIT_H

#include <stdint.h>

#include "frame.h"

#define MG_RT_SLOTS 16 /* reliable frames in flight at once; a 17th is refused */

typedef struct {
    uint8_t seq, len, retries;
    uint8_t wire[FRAME_MAX_WIRE];
    int64_t deadline_us;
} mg_rt_slot_t;

typedef struct {
    int64_t timeout_us;
    int32_t max_retries;
    int32_t n;              /* slots in use, oldest first */
    mg_rt_slot_t slot[MG_RT_SLOTS];
    int32_t n_failed;       /* given up since the last mg_rt_failed */
    uint8_t failed[MG_RT_SLOTS];
    uint32_t retransmits, acked;
} mg_retransmit_t;

void mg_rt_init(mg_retransmit_t *q, int64_t timeout_us, int32_t max_retries);
int mg_rt_contains(const mg_retransmit_t *q, uint8_t seq);
/* 1, or 0 when seq is already in flight or every slot is taken */
int mg_rt_track(mg_retransmit_t *q, uint8_t seq, const uint8_t *wire, uint8_t len,
                int64_t now_us);
int mg_rt_ack(mg_retransmit_t *q, uint8_t seq);    /* 1 if it was in flight */
int mg_rt_cancel(mg_retransmit_t *q, uint8_t seq); /* superseded: 1 if it was waiting */
/* the frames to resend at now_us, oldest first: their slot indices in *due (at most
 * MG_RT_SLOTS), valid until the queue next changes; seqs out of retries move to the failed */
int32_t mg_rt_due(mg_retransmit_t *q, int64_t now_us, int32_t *due);
/* the seqs given up since the last call, each once: their count, copied to out */
int32_t mg_rt_failed(mg_retransmit_t *q, uint8_t *out);
void mg_rt_clear(mg_retransmit_t *q);

#endif
