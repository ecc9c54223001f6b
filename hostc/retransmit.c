/* Retransmission of reliable frames (protocol/reliable.py RetransmitQueue). */
#include "retransmit.h"

#include <string.h>

void mg_rt_init(mg_retransmit_t *q, int64_t timeout_us, int32_t max_retries)
{
    memset(q, 0, sizeof *q);
    q->timeout_us = timeout_us;
    q->max_retries = max_retries;
}

static int32_t find(const mg_retransmit_t *q, uint8_t seq)
{
    for (int32_t i = 0; i < q->n; i++)
        if (q->slot[i].seq == seq)
            return i;
    return -1;
}

int mg_rt_contains(const mg_retransmit_t *q, uint8_t seq)
{
    return find(q, seq) >= 0;
}

int mg_rt_track(mg_retransmit_t *q, uint8_t seq, const uint8_t *wire, uint8_t len,
                int64_t now_us)
{
    if (find(q, seq) >= 0 || q->n >= MG_RT_SLOTS || len > FRAME_MAX_WIRE)
        return 0;
    mg_rt_slot_t *s = &q->slot[q->n++];
    s->seq = seq;
    s->len = len;
    s->retries = 0;
    memcpy(s->wire, wire, len);
    s->deadline_us = now_us + q->timeout_us;
    return 1;
}

static void drop(mg_retransmit_t *q, int32_t i)
{
    memmove(&q->slot[i], &q->slot[i + 1], (size_t)(q->n - i - 1) * sizeof q->slot[0]);
    q->n--;
}

int mg_rt_ack(mg_retransmit_t *q, uint8_t seq)
{
    const int32_t i = find(q, seq);
    if (i < 0)
        return 0;
    drop(q, i);
    q->acked++;
    return 1;
}

int mg_rt_cancel(mg_retransmit_t *q, uint8_t seq)
{
    const int32_t i = find(q, seq);
    if (i < 0)
        return 0;
    drop(q, i);
    return 1;
}

int32_t mg_rt_due(mg_retransmit_t *q, int64_t now_us, int32_t *due)
{
    int32_t n_due = 0, i = 0;
    while (i < q->n) {
        mg_rt_slot_t *s = &q->slot[i];
        if (now_us < s->deadline_us) {
            i++;
        } else if (s->retries >= q->max_retries) {
            if (q->n_failed < MG_RT_SLOTS) /* drained by every service: never full there */
                q->failed[q->n_failed++] = s->seq;
            drop(q, i);
        } else {
            s->retries++;
            s->deadline_us = now_us + q->timeout_us;
            q->retransmits++;
            due[n_due++] = i++;
        }
    }
    return n_due;
}

int32_t mg_rt_failed(mg_retransmit_t *q, uint8_t *out)
{
    const int32_t n = q->n_failed;
    memcpy(out, q->failed, (size_t)n);
    q->n_failed = 0;
    return n;
}

void mg_rt_clear(mg_retransmit_t *q)
{
    q->n = 0;
    q->n_failed = 0;
}
