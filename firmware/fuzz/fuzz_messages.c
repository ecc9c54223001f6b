/* libFuzzer target: message decoding (protocol/messages.c msg_check, protocol/joints.c) on any
 * type and payload of 0..FRAME_MAX_PAYLOAD bytes, the payload a heap copy of exactly its
 * length so that a read past it is a sanitizer report. The answer is 0 or a NACK reason the
 * protocol defines, and a reliable type is one msg_check knows. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "protocol/frame.h"
#include "protocol/messages.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0 || size > 1u + FRAME_MAX_PAYLOAD) return 0;
    uint8_t type = data[0];
    uint8_t n = (uint8_t)(size - 1u);
    uint8_t *payload = malloc(n ? n : 1u);
    if (payload == NULL) return 0;
    memcpy(payload, data + 1, n);
    uint8_t reason = msg_check(type, payload, n);
    free(payload);
    if (reason != 0 && reason != NACK_OUT_OF_RANGE && reason != NACK_BAD_LENGTH
        && reason != NACK_UNKNOWN_TYPE)
        abort();
    if (msg_is_reliable(type) && reason == NACK_UNKNOWN_TYPE) abort();
    return 0;
}
