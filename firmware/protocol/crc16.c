/* CRC-16/CCITT-FALSE: crc = (crc << 8) ^ T[(crc >> 8) ^ byte], T from poly 0x1021. */
#include "crc16.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#define CRC_TABLE_ATTR PROGMEM
#define CRC_TABLE_READ(i) pgm_read_word(&crc16_table[(i)])
#else
#define CRC_TABLE_ATTR
#define CRC_TABLE_READ(i) crc16_table[(i)]
#endif

static const uint16_t crc16_table[256] CRC_TABLE_ATTR = {
#include "crc16_table.inc"
};

uint16_t crc16_update(uint16_t crc, uint8_t byte)
{
    return (uint16_t)((uint16_t)(crc << 8) ^ CRC_TABLE_READ((uint8_t)((crc >> 8) ^ byte)));
}

uint16_t crc16_ccitt_false(const uint8_t *data, uint16_t n, uint16_t crc)
{
    for (uint16_t i = 0; i < n; i++) {
        crc = crc16_update(crc, data[i]);
    }
    return crc;
}
