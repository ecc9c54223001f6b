"""The C protocol codec (firmware/protocol), built with the host gcc and run: the golden vectors
of protocol/golden_vectors.json byte for byte, and the sources compile without a warning."""

import json
import shutil
import subprocess

import pytest

from mobigrasp.resources import data_dir

FIRMWARE = data_dir("mobigrasp.firmware")
VECTORS = data_dir("mobigrasp.protocol") / "golden_vectors.json"
GCC = shutil.which("gcc") or shutil.which("cc")
pytestmark = pytest.mark.skipif(GCC is None, reason="no host C compiler (gcc) on this machine")
CFLAGS = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O1"]


def _c_bytes(data: bytes) -> str:
    return "{" + ", ".join(f"0x{b:02x}" for b in data) + "}" if data else "{0}"


def vectors_header(data: dict) -> str:
    """vectors.h for firmware/tests/test_protocol.c from the JSON vectors."""
    lines = ["#include <stdint.h>",
             "typedef struct { uint8_t type, seq; uint16_t crc; uint8_t payload_len;",
             "  const uint8_t payload[64]; uint8_t wire_len; const uint8_t wire[71]; } golden_t;",
             "typedef struct { uint8_t wire_len; const uint8_t wire[80]; const char *counter;",
             "  uint8_t nack; } reject_t;"]
    check = bytes.fromhex(data["crc_check"]["data_hex"])
    lines.append(f"static const uint8_t CRC_CHECK_DATA[] = {_c_bytes(check)};")
    lines.append(f"#define CRC_CHECK_VALUE 0x{data['crc_check']['crc']:04x}u")
    rows = []
    for v in data["vectors"]:
        payload, wire = bytes.fromhex(v["payload_hex"]), bytes.fromhex(v["wire_hex"])
        rows.append(f"  {{{v['type']}, {v['seq']}, 0x{v['crc']:04x}, {len(payload)}, "
                    f"{_c_bytes(payload)}, {len(wire)}, {_c_bytes(wire)}}},")
    lines += [f"#define N_VECTORS {len(rows)}u", "static const golden_t VECTORS[] = {", *rows,
              "};"]
    rows = []
    for r in data["rejects"]:
        wire = bytes.fromhex(r["wire_hex"])
        counter = json.dumps(r["counter"] or "")
        rows.append(f"  {{{len(wire)}, {_c_bytes(wire)}, {counter}, {r['nack'] or 0}}},")
    lines += [f"#define N_REJECTS {len(rows)}u", "static const reject_t REJECTS[] = {", *rows,
              "};"]
    return "\n".join(lines) + "\n"


def test_c_codec_passes_the_golden_vectors(tmp_path):
    data = json.loads(VECTORS.read_text())
    (tmp_path / "vectors.h").write_text(vectors_header(data))
    exe = tmp_path / "test_protocol"
    sources = [FIRMWARE / "tests" / "test_protocol.c", *sorted((FIRMWARE / "protocol").glob("*.c"))]
    build = subprocess.run([GCC, *CFLAGS, f"-I{FIRMWARE}", f"-I{tmp_path}", "-o", str(exe),
                            *map(str, sources)], capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stdout
    checks = 1 + 5 * len(data["vectors"]) + len(data["rejects"])
    assert run.stdout.strip() == f"ok {checks}"


def test_c_codec_catches_a_wrong_vector(tmp_path):
    # the same test against a vector with one wire byte changed must fail
    data = json.loads(VECTORS.read_text())
    wire = bytearray.fromhex(data["vectors"][2]["wire_hex"])
    wire[4] ^= 0x01
    data["vectors"][2]["wire_hex"] = wire.hex(" ")
    (tmp_path / "vectors.h").write_text(vectors_header(data))
    exe = tmp_path / "test_protocol"
    sources = [FIRMWARE / "tests" / "test_protocol.c", *sorted((FIRMWARE / "protocol").glob("*.c"))]
    subprocess.run([GCC, *CFLAGS, f"-I{FIRMWARE}", f"-I{tmp_path}", "-o", str(exe),
                    *map(str, sources)], check=True, capture_output=True)
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
    assert run.returncode == 1 and "vector 3: wire bytes" in run.stdout


def test_firmware_sources_compile_without_warnings(tmp_path):
    # every file of the program and the codec, as the native backend builds them
    sources = [*sorted((FIRMWARE / "fw").glob("*.c")), *sorted((FIRMWARE / "protocol").glob("*.c")),
               FIRMWARE / "hal_native.c"]
    for src in sources:
        res = subprocess.run([GCC, *CFLAGS, "-DFW_NATIVE", f"-I{FIRMWARE}", "-c", str(src), "-o",
                              str(tmp_path / (src.stem + ".o"))], capture_output=True, text=True)
        assert res.returncode == 0, f"{src.name}: {res.stderr}"
