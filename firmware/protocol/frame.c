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
    p->stats = (frame_stats_t){0};
}

static uint8_t reject(frame_parser_t *p, uint32_t *reason, uint8_t n)
{
    (*reason)++;
    p->stats.garbage_bytes += n;
    return 0;
}

uint8_t frame_parser_feed(frame_parser_t *p, uint8_t byte)
{
    frame_stats_t *s = &p->stats;
    s->bytes_in++;
    if (p->skipping) {
        if (byte != 0) {
            s->garbage_bytes++;
        } else {
            p->skipping = 0;
        }
        return 0;
    }
    if (byte != 0) {
        if (p->len == FRAME_MAX_ENCODED) { /* one byte more than any frame */
            s->oversize++;
            s->garbage_bytes += FRAME_MAX_ENCODED + 1u;
            p->len = 0;
            p->skipping = 1;
            return 0;
        }
        p->buf[p->len++] = byte;
        return 0;
    }
    uint8_t n = p->len;
    p->len = 0;
    if (n == 0) {
        return 0; /* idle delimiter */
    }
    if (!cobs_decode_in_place(p->buf, n)) {
        return reject(p, &s->cobs_errors, n);
    }
    if (n < FRAME_MIN_RAW + 1u) {
        return reject(p, &s->truncated, n);
    }
    uint16_t crc = crc16_ccitt_false(p->buf + 1, (uint16_t)(n - 3u), CRC16_INIT);
    if (crc != (uint16_t)(p->buf[n - 2] | ((uint16_t)p->buf[n - 1] << 8))) {
        return reject(p, &s->crc_errors, n);
    }
    if (p->buf[1] != PROTOCOL_VERSION && p->buf[3] != FRAME_VERSION_FREE_TYPE) {
        return reject(p, &s->bad_version, n);
    }
    s->frames_ok++;
    return (uint8_t)(n - FRAME_MIN_RAW); /* payload length + 1 */
}
