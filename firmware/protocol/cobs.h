/* Consistent Overhead Byte Stuffing (Cheshire and Baker, 1999) for frames under 254 bytes,
 * which every frame of the protocol is (protocol/cobs.py is the reference). */
#ifndef MOBIGRASP_COBS_H
#define MOBIGRASP_COBS_H

#include <stdint.h>

/* Encode ``n`` (< 254) bytes held at buf[1..n] in place into buf[0..n]: the byte at buf[0] is
 * overwritten with the first code byte. Returns n + 1, the encoded length (no delimiter). */
uint8_t cobs_encode_in_place(uint8_t *buf, uint8_t n);

/* Decode ``n`` zero-free encoded bytes in place: every code byte becomes the zero it stands
 * for, so the decoded data is buf[1..n-1]. Returns 0 if a code byte points past the end. */
uint8_t cobs_decode_in_place(uint8_t *buf, uint8_t n);

#endif
