/* Frames of the serial protocol (docs/protocol.md, protocol/frame.py is the reference):
 *
 *     COBS( version u8 | seq u8 | msg_type u8 | payload 0..64 | crc16 u16 LE ) | 0x00
 *
 * The CRC is CRC-16/CCITT-FALSE over version..payload. The parser takes one byte at a time (the
 * main loop drains the RX ring into it) and counts every run it rejects under one reason, with
 * the same counters and totals as protocol.FrameParser whatever the chunking. A run that fails
 * as one frame (oversize, COBS or CRC error) is searched for a valid frame ending at its 0x00
 * (docs/protocol.md 2.1): when a delimiter is lost only the frame before it is lost. */
#ifndef MOBIGRASP_FRAME_H
#define MOBIGRASP_FRAME_H

#include <stdint.h>

#define PROTOCOL_VERSION 1u
#define FRAME_MAX_PAYLOAD 64u
#define FRAME_HEADER_LEN 3u
#define FRAME_CRC_LEN 2u
#define FRAME_MIN_RAW (FRAME_HEADER_LEN + FRAME_CRC_LEN)
#define FRAME_MAX_RAW (FRAME_HEADER_LEN + FRAME_MAX_PAYLOAD + FRAME_CRC_LEN) /* 69 */
#define FRAME_MAX_ENCODED (FRAME_MAX_RAW + 1u)                              /* 70 */
#define FRAME_MAX_WIRE (FRAME_MAX_ENCODED + 1u)                             /* 71 */
#define FRAME_VERSION_FREE_TYPE 0x01u /* HELLO keeps its layout in every version */

/* A frame being built: payload at frame_payload(buf), then frame_finish(). ``buf`` holds
 * FRAME_MAX_WIRE bytes. */
#define FRAME_PAYLOAD_OFFSET 4u
static inline uint8_t *frame_payload(uint8_t *buf) { return buf + FRAME_PAYLOAD_OFFSET; }

/* Header, CRC, COBS and delimiter around the ``n`` payload bytes already at frame_payload(buf);
 * returns the wire length (n + 7). */
uint8_t frame_finish(uint8_t *buf, uint8_t seq, uint8_t msg_type, uint8_t n);

typedef struct {
    uint32_t frames_ok;
    uint32_t crc_errors;
    uint32_t oversize;
    uint32_t unknown_type; /* the firmware accepts every type (it NACKs unknown ones) */
    uint32_t bad_version;
    uint32_t truncated;
    uint32_t cobs_errors;
    uint32_t garbage_bytes; /* bytes not delivered in a frame */
    uint32_t bytes_in;
    uint32_t recovered; /* frames found at the end of a rejected run (its delimiter was lost) */
} frame_stats_t;

typedef struct {
    uint8_t buf[FRAME_MAX_ENCODED]; /* encoded bytes up to the delimiter, decoded in place */
    uint8_t len;
    uint8_t skipping; /* inside a run longer than any frame: buf is a ring of its last bytes */
    uint8_t start;    /* while skipping: index of the oldest byte kept */
    frame_stats_t stats;
} frame_parser_t;

void frame_parser_reset(frame_parser_t *p); /* partial frame and counters */

/* One received byte. Returns the payload length + 1 (1..65) when it completed a valid frame,
 * whose fields are then frame_version(p), frame_seq(p), frame_type(p), frame_data(p); else 0. */
uint8_t frame_parser_feed(frame_parser_t *p, uint8_t byte);

static inline uint8_t frame_version(const frame_parser_t *p) { return p->buf[1]; }
static inline uint8_t frame_seq(const frame_parser_t *p) { return p->buf[2]; }
static inline uint8_t frame_type(const frame_parser_t *p) { return p->buf[3]; }
static inline const uint8_t *frame_data(const frame_parser_t *p) { return p->buf + 4; }
/* The frame's CRC-16 field (the duplicate filter tells copies by it). */
static inline uint16_t frame_crc(const frame_parser_t *p, uint8_t payload_len)
{
    return (uint16_t)(p->buf[4 + payload_len] | ((uint16_t)p->buf[5 + payload_len] << 8));
}

#endif
