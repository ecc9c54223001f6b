/* libFuzzer target: COBS (protocol/cobs.c) both ways. Any input of 1..253 bytes encodes in
 * place and decodes back to itself; the encoding holds no zero. Any zero-free run decodes in
 * place without reading or writing past its end (the sanitizers watch the buffer's bounds:
 * it is a heap copy of exactly the run). */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "protocol/cobs.h"

#define COBS_MAX_DATA 253u

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0 || size > COBS_MAX_DATA) return 0;
    uint8_t n = (uint8_t)size;
    uint8_t buf[COBS_MAX_DATA + 1u];
    memcpy(buf + 1, data, n);
    uint8_t enc = cobs_encode_in_place(buf, n);
    if (enc != n + 1u) abort();
    for (uint8_t i = 0; i < enc; i++) {
        if (buf[i] == 0) abort();
    }
    if (cobs_decode_in_place(buf, enc) == 0) abort();
    if (memcmp(buf + 1, data, n) != 0) abort();

    /* the raw input as a received run: up to its first zero, the way the parser hands it over */
    size_t run = 0;
    while (run < size && data[run] != 0) run++;
    if (run == 0) return 0;
    uint8_t *copy = malloc(run); /* exactly the run: one byte past it is a sanitizer report */
    if (copy == NULL) return 0;
    memcpy(copy, data, run);
    (void)cobs_decode_in_place(copy, (uint8_t)run);
    free(copy);
    return 0;
}
