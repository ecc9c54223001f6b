import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.protocol.cobs import cobs_decode, cobs_encode
from mobigrasp.protocol.crc import crc16_ccitt_false, crc16_ccitt_false_table


def crc_bitwise(data: bytes) -> int:
    """Textbook MSB-first CRC-16/CCITT-FALSE, bit by bit: the float-free reference."""
    crc = 0xFFFF
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return crc


def test_crc_check_value():
    assert crc16_ccitt_false(b"123456789") == 0x29B1
    assert crc16_ccitt_false_table(b"123456789") == 0x29B1
    assert crc16_ccitt_false(b"") == 0xFFFF


@examples(200)
@given(st.binary(max_size=300), st.integers(0, 300))
def test_crc_implementations_agree_and_chain(data, cut):
    expected = crc_bitwise(data)
    assert crc16_ccitt_false(data) == expected
    assert crc16_ccitt_false_table(data) == expected
    assert crc16_ccitt_false(data[cut:], crc16_ccitt_false(data[:cut])) == expected


# Examples from Cheshire & Baker's COBS paper / the common reference set.
COBS_VECTORS = [
    (b"", b"\x01"),
    (b"\x00", b"\x01\x01"),
    (b"\x00\x00", b"\x01\x01\x01"),
    (b"\x11\x22\x00\x33", b"\x03\x11\x22\x02\x33"),
    (b"\x11\x22\x33\x44", b"\x05\x11\x22\x33\x44"),
    (b"\x11\x00\x00\x00", b"\x02\x11\x01\x01\x01"),
    (bytes(range(1, 255)), b"\xff" + bytes(range(1, 255)) + b"\x01"),
]


@pytest.mark.parametrize("raw,enc", COBS_VECTORS)
def test_cobs_vectors(raw, enc):
    assert cobs_encode(raw) == enc
    assert cobs_decode(enc) == raw


@examples(200)
@given(st.binary(max_size=700))
def test_cobs_roundtrip_has_no_zero_and_bounded_overhead(data):
    enc = cobs_encode(data)
    assert 0 not in enc
    assert len(enc) <= len(data) + 1 + len(data) // 254
    assert cobs_decode(enc) == data


@pytest.mark.parametrize("bad", [b"", b"\x00", b"\x03\x11", b"\x02\x00", b"\x05\x11\x22"])
def test_cobs_decode_rejects_invalid(bad):
    with pytest.raises(ValueError, match="cobs_decode"):
        cobs_decode(bad)
