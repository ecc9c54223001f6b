/* libFuzzer target: any byte stream into the frame parser both boards use (protocol/frame.c),
 * and every frame it delivers into msg_check. Checked beyond the sanitizers: a delivered
 * payload is at most FRAME_MAX_PAYLOAD bytes, carries PROTOCOL_VERSION (or is a HELLO), and
 * every input byte is counted once (bytes_in); a rejected run is counted under one reason, so
 * the counters never exceed the bytes seen. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "protocol/frame.h"
#include "protocol/messages.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static frame_parser_t p; /* static: no allocation, as on the boards */
    frame_parser_reset(&p);
    uint32_t delivered = 0;
    for (size_t i = 0; i < size; i++) {
        uint8_t got = frame_parser_feed(&p, data[i]);
        if (got) {
            uint8_t n = (uint8_t)(got - 1u);
            if (n > FRAME_MAX_PAYLOAD) abort();
            if (frame_version(&p) != PROTOCOL_VERSION && frame_type(&p) != FRAME_VERSION_FREE_TYPE)
                abort();
            uint8_t reason = msg_check(frame_type(&p), frame_data(&p), n);
            if (reason > NACK_SEQ_REUSED) abort();
            (void)msg_is_reliable(frame_type(&p));
            delivered++;
        }
    }
    const frame_stats_t *s = &p.stats;
    if (s->bytes_in != (uint32_t)size || s->frames_ok != delivered) abort();
    uint32_t rejected = s->crc_errors + s->oversize + s->unknown_type + s->bad_version
                        + s->truncated + s->cobs_errors;
    if (rejected > (uint32_t)size || s->garbage_bytes > (uint32_t)size) abort();
    return 0;
}
