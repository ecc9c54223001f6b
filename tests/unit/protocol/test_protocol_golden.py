"""Golden vectors of docs/protocol.md §7, checked both ways: the message encodes to exactly the
documented bytes, and the documented bytes parse to exactly the message. The vectors are also
written out here so that a change to the document alone cannot make this test pass."""

import json
import re
from pathlib import Path

import pytest

import mobigrasp.protocol as p
from mobigrasp.resources import data_dir

DOC = Path(__file__).resolve().parents[3] / "docs" / "protocol.md"

GOLDEN = [
    (p.Hello(1, "s3c2440-host", 1), 0,
     "02 01 04 01 01 01 0f 73 33 63 32 34 34 30 2d 68 6f 73 74 e6 d9 00"),
    (p.HelloAck(1, "atmega128-fw-0.1", 3), 0,
     "02 01 04 02 01 03 13 61 74 6d 65 67 61 31 32 38 2d 66 77 2d 30 2e 31 a2 6a 00"),
    (p.Heartbeat(1_000_000), 1, "07 01 01 03 40 42 0f 03 b2 ef 00"),
    (p.SetServos(0, (1000, 1500, 1500, 1500, 1500, 1500), 0), 2,
     "04 01 02 10 0d e8 03 dc 05 dc 05 dc 05 dc 05 dc 05 01 03 69 e1 00"),
    (p.SetServos(1, (0, 0, -1571, -1571, 1571, 0), 500), 3,
     "05 01 03 10 01 01 01 01 07 dd f9 dd f9 23 06 01 05 f4 01 e0 c8 00"),
    (p.Gripper(800), 4, "08 01 04 11 20 03 7a 33 00"),
    (p.SetWheels(150, -150), 5, "05 01 05 12 96 05 6a ff 60 51 00"),
    (p.Stop(), 6, "06 01 06 13 58 73 00"),
    (p.Telemetry(20_000, 1024, -512, (1000, 1500, 1500, 1500, 1500, 1500),
                 (350, 1200, 0xFFFF, 0xFFFF, 0xFFFF), p.FLAG_HANDSHAKE | p.FLAG_RESET, 0, 0, 1, 0),
     0,
     "02 01 04 20 20 4e 01 01 02 04 01 01 1b fe ff ff e8 03 dc 05 dc 05 dc 05 dc 05 dc 05 5e 01 "
     "b0 04 ff ff ff ff ff ff 14 01 01 01 01 02 01 01 01 03 4c 60 00"),
    (p.ParamGet(1), 7, "05 01 07 30 01 03 e4 1c 00"),
    (p.ParamSet(1, 250), 8, "05 01 08 31 01 02 fa 01 01 03 21 be 00"),
    (p.ParamValue(1, 250), 9, "05 01 09 32 01 02 fa 01 01 03 70 21 00"),
    (p.Ack(2), 10, "07 01 0a 40 02 3b 18 00"),
    (p.Nack(3, p.NACK_OUT_OF_RANGE), 11, "08 01 0b 41 03 01 ad ca 00"),
    (p.Log(42, "sonar 3 timeout"), 12,
     "05 01 0c 50 2a 12 73 6f 6e 61 72 20 33 20 74 69 6d 65 6f 75 74 a4 8d 00"),
]


ROW = r"\| (\d+) \| `(.+)` \| (\d+) \| (.+?) \| 0x([0-9A-F]{4}) \| `([0-9a-f ]+)` \|"


def _doc_rows():
    text = DOC.read_text()
    section = text[text.index("## 7. Golden vectors"):text.index("### 7.1")]
    rows = []
    for line in section.splitlines():
        m = re.match(ROW, line)
        if m:
            rows.append((m.group(2), int(m.group(3)), m.group(4), int(m.group(5), 16),
                         m.group(6)))
    return rows


def test_every_message_type_has_a_vector():
    assert {type(msg) for msg, _, _ in GOLDEN} == set(p.ALL_MESSAGES)


@pytest.mark.parametrize("msg,seq,wire_hex", GOLDEN, ids=lambda v: getattr(v, "__name__", None))
def test_golden_both_ways(msg, seq, wire_hex):
    wire = bytes.fromhex(wire_hex)
    assert p.encode_message(msg, seq) == wire
    parser = p.FrameParser(known_types=p.MESSAGE_TYPES)
    frames = parser.feed(wire)
    assert len(frames) == 1 and frames[0].seq == seq
    assert p.decode_frame(frames[0]) == msg
    assert parser.stats.frames_ok == 1 and parser.stats.garbage_bytes == 0


def test_document_table_matches_the_vectors():
    rows = _doc_rows()
    assert len(rows) == len(GOLDEN)
    for (text, seq, payload_hex, crc, wire_hex), (msg, g_seq, g_wire) in zip(
            rows, GOLDEN, strict=True):
        assert text == repr(msg) and seq == g_seq and wire_hex == g_wire
        payload = b"" if "empty" in payload_hex else bytes.fromhex(payload_hex.strip("`"))
        assert payload == msg.encode()
        raw = bytes((1, seq, msg.MSG_TYPE)) + payload
        assert p.crc16_ccitt_false(raw) == crc


REJECTS = [
    ("06 01 06 13 58 72 00", "crc_errors", None),
    ("06 02 06 13 08 2a 00", "bad_version", None),
    ("06 01 06 7f 72 de 00", "unknown_type", p.NACK_UNKNOWN_TYPE),
    ("07 01 06 13 01 d5 06 00", None, p.NACK_BAD_LENGTH),
    ("08 01 04 11 e9 03 b6 9f 00", None, p.NACK_OUT_OF_RANGE),
    ("03 01 06 00", "truncated", None),
    ("09 01 06 13 00", "cobs_errors", None),
]


@pytest.mark.parametrize("wire_hex,counter,nack", REJECTS)
def test_documented_reject_vectors(wire_hex, counter, nack):
    assert f"`{wire_hex}`" in DOC.read_text()
    wire = bytes.fromhex(wire_hex)
    filtered = p.FrameParser(known_types=p.MESSAGE_TYPES)
    frames = filtered.feed(wire)
    if counter is not None:
        assert frames == [] and filtered.stats.as_dict()[counter] == 1
    if nack is not None:
        (frame,) = p.FrameParser().feed(wire)  # delivered when types are not filtered
        with pytest.raises(p.MessageError) as info:
            p.decode_frame(frame)
        assert info.value.nack_reason == nack


def test_crc_check_value_documented():
    assert "0x29B1" in DOC.read_text() and p.crc16_ccitt_false(b"123456789") == 0x29B1
    assert p.encode_message(p.Stop(), 0).hex(" ") == "02 01 04 13 fe d9 00"
    assert "`02 01 04 13 fe d9`" in DOC.read_text()


VECTORS_JSON = data_dir("mobigrasp.protocol") / "golden_vectors.json"


def test_json_vectors_are_the_documented_ones():
    # protocol/golden_vectors.json is what the C unit test reads (unit/mcu_sim/test_firmware_c.py)
    data = json.loads(VECTORS_JSON.read_text())
    assert data["crc_check"] == {"data_hex": b"123456789".hex(), "crc": 0x29B1}
    assert len(data["vectors"]) == len(GOLDEN)
    for vec, (msg, seq, wire_hex) in zip(data["vectors"], GOLDEN, strict=True):
        payload = bytes.fromhex(vec["payload_hex"])
        assert vec["message"] == repr(msg) and vec["seq"] == seq and vec["type"] == msg.MSG_TYPE
        assert vec["wire_hex"] == wire_hex and payload == msg.encode()
        assert vec["crc"] == p.crc16_ccitt_false(bytes((1, seq, msg.MSG_TYPE)) + payload)
        assert p.encode_frame(p.Frame(1, seq, msg.MSG_TYPE, payload)) == bytes.fromhex(wire_hex)
    assert [(r["wire_hex"], r["counter"], r["nack"]) for r in data["rejects"]] == REJECTS
