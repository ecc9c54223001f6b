"""Consistent Overhead Byte Stuffing (Cheshire and Baker, 1999): frames that never contain 0x00.

The encoded form replaces every zero by a "code" byte giving the distance to the next zero, so the
only 0x00 on the wire is the frame delimiter. A receiver that loses bytes or starts listening in
the middle of a frame therefore resynchronises at the very next 0x00, whatever the payload holds.
Overhead: one byte per started 254 bytes of input (one byte for every frame of this protocol).
"""

from __future__ import annotations


def cobs_encode(data: bytes) -> bytes:
    """COBS-encode ``data``; the result has no 0x00 byte and no delimiter appended."""
    data = bytes(data)
    if len(data) < 254:  # every frame of the protocol: each block gets one code byte, its
        # length + 1, and no block needs a 0xFF split; done in C (map) instead of a loop
        blocks = data.split(b"\x00")
        return b"".join(map(bytes.__add__, map(_CODE_FOR_LEN.__getitem__, map(len, blocks)),
                            blocks))
    parts: list[bytes] = []  # joined once at the end (fewer copies than a growing bytearray)
    for block in data.split(b"\x00"):
        # Each zero-free block becomes runs of at most 254 bytes; a 0xFF code means "254 data
        # bytes and no implied zero", so long blocks are cut there.
        while len(block) >= 254:
            parts.append(b"\xff")
            parts.append(block[:254])
            block = block[254:]
        parts.append(_CODE_BYTE[len(block) + 1])
        parts.append(block)
    return b"".join(parts)


_CODE_BYTE = tuple(bytes((i,)) for i in range(256))  # code byte values as 1-byte strings
_CODE_FOR_LEN = _CODE_BYTE[1:]  # the code byte of a block of n < 254 bytes: n + 1


def cobs_decode(data: bytes) -> bytes:
    """Decode one COBS frame (without its delimiter); ValueError if it is not valid COBS."""
    data = bytes(data)
    if not data:
        raise ValueError("cobs_decode: empty input (the encoding of b'' is b'\\x01')")
    if 0 in data:
        raise ValueError(f"cobs_decode: 0x00 inside an encoded frame at offset {data.index(0)}")
    return decode_zero_free(data)


def decode_zero_free(data: bytes) -> bytes:
    """Decode COBS bytes already known to contain no 0x00 (as after splitting on delimiters)."""
    n = len(data)
    code = data[0]
    if code == n:  # the common case: one group, no zero in the original
        return data[1:]
    out = bytearray()
    i = 0
    while i < n:
        code = data[i]
        end = i + code
        if end > n:
            raise ValueError(
                f"cobs_decode: code byte {code} at offset {i} runs past the end ({n} bytes)"
            )
        out += data[i + 1:end]
        i = end
        if code != 0xFF and i < n:
            out.append(0)
    return bytes(out)
