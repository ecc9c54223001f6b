/* The C side of the differential fuzz against protocol.FrameParser (tools/benches/fuzz.py):
 * a whole input through frame_parser_feed in one call, each delivered frame written out as
 * payload length, version, seq, type, payload; and msg_check on each. */
#include "diff_feed.h"

#include "protocol/messages.h"

uint32_t diff_feed(frame_parser_t *p, const uint8_t *in, uint32_t n, uint8_t *out, uint32_t cap)
{
    uint32_t used = 0;
    for (uint32_t i = 0; i < n; i++) {
        uint8_t got = frame_parser_feed(p, in[i]);
        if (got) {
            uint8_t len = (uint8_t)(got - 1u);
            if (used + 5u + len > cap) return used;
            out[used] = len;
            out[used + 1u] = frame_version(p);
            out[used + 2u] = frame_seq(p);
            out[used + 3u] = frame_type(p);
            out[used + 4u] = msg_check(frame_type(p), frame_data(p), len);
            for (uint8_t k = 0; k < len; k++) out[used + 5u + k] = frame_data(p)[k];
            used += 5u + len;
        }
    }
    return used;
}
