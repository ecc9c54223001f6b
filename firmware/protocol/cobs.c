/* COBS for blocks under 254 bytes: no 0xFF "254 bytes, no zero" codes are ever produced, and
 * an encoded frame longer than a valid one is refused by the parser before it gets here. */
#include "cobs.h"

uint8_t cobs_encode_in_place(uint8_t *buf, uint8_t n)
{
    /* buf[1..n] is the data; each zero becomes the code of the block before it, the code of
     * the first block goes to buf[0]: the output index of a byte equals its input index. */
    uint8_t code_at = 0;
    uint8_t code = 1;
    for (uint8_t i = 1; i <= n; i++) {
        if (buf[i] == 0) {
            buf[code_at] = code;
            code_at = i;
            code = 1;
        } else {
            code++;
        }
    }
    buf[code_at] = code;
    return (uint8_t)(n + 1);
}

uint8_t cobs_decode_in_place(uint8_t *buf, uint8_t n)
{
    uint16_t i = 0;
    while (i < n) {
        uint8_t code = buf[i];
        if (code == 0) {
            return 0; /* not zero-free: the caller split on the delimiter wrongly */
        }
        buf[i] = 0;
        i = (uint16_t)(i + code);
    }
    return i == n;
}
