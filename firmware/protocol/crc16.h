/* CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, xorout 0): the frame check of
 * docs/protocol.md. Table-driven, the table in flash on the AVR (protocol/crc.py is the
 * reference). */
#ifndef MOBIGRASP_CRC16_H
#define MOBIGRASP_CRC16_H

#include <stdint.h>

#define CRC16_INIT 0xFFFFu

uint16_t crc16_update(uint16_t crc, uint8_t byte);
uint16_t crc16_ccitt_false(const uint8_t *data, uint16_t n, uint16_t crc);

#endif
