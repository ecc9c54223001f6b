/* Host-gcc unit test of the C protocol codec against the golden vectors of docs/protocol.md
 * (protocol/golden_vectors.json, turned into vectors.h by tests/test_firmware_c.py): CRC, frame
 * encoding byte for byte, the parser's frames and counters, and msg_check's NACK reasons.
 * Prints one line per failure and "ok N" at the end; exit status 1 on any failure. */
#include <stdio.h>
#include <string.h>

#include "protocol/crc16.h"
#include "protocol/frame.h"
#include "protocol/messages.h"
#include "vectors.h"

static int failures;
static int checks;

#define CHECK(cond, ...) do { checks++; if (!(cond)) { failures++; printf("FAIL %s:%d: ", \
    __FILE__, __LINE__); printf(__VA_ARGS__); printf("\n"); } } while (0)

static uint32_t counter(const frame_stats_t *s, const char *name)
{
    if (!strcmp(name, "crc_errors")) return s->crc_errors;
    if (!strcmp(name, "bad_version")) return s->bad_version;
    if (!strcmp(name, "unknown_type")) return s->unknown_type;
    if (!strcmp(name, "truncated")) return s->truncated;
    if (!strcmp(name, "cobs_errors")) return s->cobs_errors;
    if (!strcmp(name, "oversize")) return s->oversize;
    return 0xFFFFFFFFu;
}

int main(void)
{
    CHECK(crc16_ccitt_false(CRC_CHECK_DATA, sizeof CRC_CHECK_DATA, CRC16_INIT) == CRC_CHECK_VALUE,
          "check value");
    for (unsigned v = 0; v < N_VECTORS; v++) {
        const golden_t *g = &VECTORS[v];
        uint8_t buf[FRAME_MAX_WIRE];
        memcpy(frame_payload(buf), g->payload, g->payload_len);
        uint8_t raw[FRAME_MAX_RAW];
        raw[0] = PROTOCOL_VERSION;
        raw[1] = g->seq;
        raw[2] = g->type;
        memcpy(raw + 3, g->payload, g->payload_len);
        CHECK(crc16_ccitt_false(raw, (uint16_t)(3 + g->payload_len), CRC16_INIT) == g->crc,
              "vector %u: crc", v + 1);
        uint8_t len = frame_finish(buf, g->seq, g->type, g->payload_len);
        CHECK(len == g->wire_len && !memcmp(buf, g->wire, len), "vector %u: wire bytes", v + 1);
        frame_parser_t p;
        frame_parser_reset(&p);
        unsigned frames = 0;
        for (unsigned i = 0; i < g->wire_len; i++) {
            uint8_t n = frame_parser_feed(&p, g->wire[i]);
            if (n) {
                frames++;
                CHECK(n - 1u == g->payload_len && frame_seq(&p) == g->seq
                      && frame_type(&p) == g->type && frame_version(&p) == PROTOCOL_VERSION
                      && !memcmp(frame_data(&p), g->payload, g->payload_len),
                      "vector %u: parsed frame", v + 1);
                CHECK(msg_check(g->type, frame_data(&p), (uint8_t)(n - 1u)) == 0,
                      "vector %u: payload decodes", v + 1);
            }
        }
        CHECK(frames == 1 && p.stats.frames_ok == 1 && p.stats.garbage_bytes == 0
              && p.stats.bytes_in == g->wire_len, "vector %u: one frame, no garbage", v + 1);
    }
    for (unsigned r = 0; r < N_REJECTS; r++) {
        const reject_t *j = &REJECTS[r];
        frame_parser_t p;
        frame_parser_reset(&p);
        uint8_t delivered = 0;
        uint8_t reason = 0;
        for (unsigned i = 0; i < j->wire_len; i++) {
            uint8_t n = frame_parser_feed(&p, j->wire[i]);
            if (n) {
                delivered = 1;
                reason = msg_check(frame_type(&p), frame_data(&p), (uint8_t)(n - 1u));
            }
        }
        if (j->nack) { /* the firmware takes every type: delivered, then NACKed */
            CHECK(delivered && reason == j->nack, "reject %u: NACK %u, got %u", r + 1,
                  j->nack, reason);
        } else {
            CHECK(!delivered && counter(&p.stats, j->counter) == 1
                  && p.stats.garbage_bytes == j->wire_len - 1u,
                  "reject %u: counted as %s", r + 1, j->counter);
        }
    }
    printf("ok %d\n", checks - failures);
    return failures ? 1 : 0;
}
