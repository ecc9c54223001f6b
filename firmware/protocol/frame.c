/* Frame encoding and the byte-at-a-time stream parser (protocol/frame.py, FrameParser). */
#include "frame.h"

#include "cobs.h"
#include "crc16.h"

uint8_t frame_finish(uint8_t *buf, uint8_t seq, uint8_t msg_type, uint8_t n)
{
    buf[1] = PROTOCOL_VERSION;
    buf[2] = seq;
    buf[3] = msg_type;
    uint8_t raw = (uint8_t)(FRAME_HEADER_LEN + n);
    uint16_t crc = crc16_ccitt_false(buf + 1, raw, CRC16_INIT);
    buf[1 + raw] = (uint8_t)(crc & 0xFFu);
    buf[2 + raw] = (uint8_t)(crc >> 8);
    uint8_t len = cobs_encode_in_place(buf, (uint8_t)(raw + FRAME_CRC_LEN));
    buf[len] = 0;
    return (uint8_t)(len + 1);
}

void frame_parser_reset(frame_parser_t *p)
{
    p->len = 0;
    p->skipping = 0;
    p->start = 0;
    p->stats = (frame_stats_t){0};
}

enum { CHECK_OK, CHECK_COBS, CHECK_TRUNCATED, CHECK_CRC, CHECK_VERSION };

/* The checks of docs/protocol.md 2.4 on the ``n`` encoded bytes at ``e``, without changing them:
 * the COBS code chain, the length, the CRC over the decoded bytes (a code position decodes to
 * 0), the version rule. */
static uint8_t check(const uint8_t *e, uint8_t n)
{
    uint16_t i = 0;
    while (i < n) {
        i = (uint16_t)(i + e[i]);
    }
    if (i != n) {
        return CHECK_COBS;
    }
    if (n < FRAME_MIN_RAW + 1u) {
        return CHECK_TRUNCATED;
    }
    uint16_t crc = CRC16_INIT;
    uint16_t code_at = e[0];
    uint8_t raw[FRAME_MIN_RAW + 1u]; /* decoded bytes 1..3 and the last two */
    for (uint8_t k = 1; k < n; k++) {
        uint8_t byte = e[k];
        if (k == code_at) {
            code_at = (uint16_t)(code_at + e[k]);
            byte = 0;
        }
        if (k <= 3u) {
            raw[k] = byte;
        } else if (k >= n - 2u) {
            raw[4 + k - (n - 2u)] = byte;
            continue;
        }
        if (k < n - 2u) {
            crc = crc16_update(crc, byte);
        }
    }
    if (crc != (uint16_t)(raw[4] | ((uint16_t)raw[5] << 8))) {
        return CHECK_CRC;
    }
    if (raw[1] != PROTOCOL_VERSION && raw[3] != FRAME_VERSION_FREE_TYPE) {
        return CHECK_VERSION;
    }
    return CHECK_OK;
}

/* Deliver the valid frame of ``n`` encoded bytes at buf + j: moved to the front, decoded. */
static uint8_t deliver(frame_parser_t *p, uint8_t j, uint8_t n)
{
    for (uint8_t k = 0; k < n; k++) {
        p->buf[k] = p->buf[j + k];
    }
    cobs_decode_in_place(p->buf, n);
    p->stats.frames_ok++;
    return (uint8_t)(n - FRAME_MIN_RAW); /* payload length + 1 */
}

/* The run buf[0..n-1] (ending at a 0x00) was rejected and counted: deliver its longest suffix
 * from offset ``first`` on that is a valid frame, if any; the rest is garbage. Starts whose
 * code chain ends exactly at n are marked from the end in a bitmap (docs/protocol.md 2.1). */
static uint8_t recover(frame_parser_t *p, uint8_t n, uint8_t first)
{
    uint8_t ok[(FRAME_MAX_ENCODED + 8u) / 8u + 1u] = {0};
    ok[n >> 3] |= (uint8_t)(1u << (n & 7u));
    for (int16_t i = (int16_t)n - 1; i >= 0; i--) {
        uint16_t next = (uint16_t)(i + p->buf[i]);
        if (next <= n && (ok[next >> 3] & (1u << (next & 7u)))) {
            ok[i >> 3] |= (uint8_t)(1u << (i & 7u));
        }
    }
    for (uint8_t j = first; (uint8_t)(n - j) >= FRAME_MIN_RAW + 1u && j < n; j++) {
        if ((ok[j >> 3] & (1u << (j & 7u))) && check(p->buf + j, (uint8_t)(n - j)) == CHECK_OK) {
            p->stats.recovered++;
            p->stats.garbage_bytes += j;
            return deliver(p, j, (uint8_t)(n - j));
        }
    }
    p->stats.garbage_bytes += n;
    return 0;
}

static void reverse(uint8_t *b, uint8_t lo, uint8_t hi) /* b[lo..hi-1] */
{
    while (lo + 1u < hi) {
        uint8_t t = b[lo];
        b[lo++] = b[--hi];
        b[hi] = t;
    }
}

uint8_t frame_parser_feed(frame_parser_t *p, uint8_t byte)
{
    frame_stats_t *s = &p->stats;
    s->bytes_in++;
    if (byte != 0) {
        if (p->skipping) { /* keep the last FRAME_MAX_ENCODED bytes of the run, as a ring */
            s->garbage_bytes++;
            p->buf[p->start] = byte;
            p->start = (uint8_t)((p->start + 1u) % FRAME_MAX_ENCODED);
        } else if (p->len == FRAME_MAX_ENCODED) { /* one byte more than any frame */
            s->oversize++;
            s->garbage_bytes++;
            p->buf[0] = byte; /* the oldest byte is dropped: the ring starts after this one */
            p->start = 1;
            p->skipping = 1;
        } else {
            p->buf[p->len++] = byte;
        }
        return 0;
    }
    uint8_t n = p->len;
    p->len = 0;
    if (p->skipping) { /* the oversize run ends here: put its bytes in order, search them */
        p->skipping = 0;
        reverse(p->buf, 0, p->start);
        reverse(p->buf, p->start, FRAME_MAX_ENCODED);
        reverse(p->buf, 0, FRAME_MAX_ENCODED);
        return recover(p, FRAME_MAX_ENCODED, 0);
    }
    if (n == 0) {
        return 0; /* idle delimiter */
    }
    switch (check(p->buf, n)) {
    case CHECK_COBS:
        s->cobs_errors++;
        return recover(p, n, 1);
    case CHECK_TRUNCATED:
        s->truncated++;
        s->garbage_bytes += n;
        return 0;
    case CHECK_CRC:
        s->crc_errors++;
        return recover(p, n, 1);
    case CHECK_VERSION:
        s->bad_version++;
        s->garbage_bytes += n;
        return 0;
    default:
        return deliver(p, 0, n);
    }
}
