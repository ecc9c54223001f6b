"""CRC-16/CCITT-FALSE, the frame check of the mobigrasp serial protocol.

Parameters (Rocksoft model): width 16, poly 0x1021, init 0xFFFF, refin false, refout false,
xorout 0x0000, check value 0x29B1 for b"123456789". ``binascii.crc_hqx`` computes exactly this
CRC when given ``0xFFFF`` as its start value, in C; the table-driven version below is the one the
ATmega128 side ports (a 512-byte table in flash, or the 4-shift form of ``_crc_ccitt_update`` in
avr-libc's ``util/crc16.h``) and is checked against ``crc_hqx`` by the tests.
"""

from __future__ import annotations

import binascii

CRC16_INIT = 0xFFFF
CRC16_POLY = 0x1021
CRC16_CHECK = 0x29B1  # CRC of b"123456789"


def _make_table() -> tuple[int, ...]:
    table = []
    for byte in range(256):
        crc = byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ CRC16_POLY) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
        table.append(crc)
    return tuple(table)


CRC16_TABLE: tuple[int, ...] = _make_table()


def crc16_ccitt_false(data: bytes, crc: int = CRC16_INIT) -> int:
    """CRC-16/CCITT-FALSE of ``data`` continuing from ``crc`` (0xFFFF to start a new one)."""
    return binascii.crc_hqx(data, crc)


def crc16_ccitt_false_table(data: bytes, crc: int = CRC16_INIT) -> int:
    """The same CRC, byte by byte from a 256-entry table, as the C side computes it."""
    table = CRC16_TABLE
    for byte in data:
        crc = ((crc << 8) & 0xFFFF) ^ table[((crc >> 8) ^ byte) & 0xFF]
    return crc
