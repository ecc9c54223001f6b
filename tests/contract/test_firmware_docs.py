"""docs/firmware.md stays in step with the code: PARAM table rows, SRAM total, telemetry layout."""

from pathlib import Path

from mobigrasp.mcu_sim.firmware import sram
from mobigrasp.mcu_sim.firmware.params import PARAM_TABLE
from mobigrasp.mcu_sim.firmware.program import TELEMETRY_STRUCT
from mobigrasp.protocol import Telemetry

DOC = (Path(__file__).resolve().parents[2] / "docs" / "firmware.md").read_text()


def test_every_param_row_is_documented():
    for pid, name, default, lo, hi, writable, safety in PARAM_TABLE:
        row = (f"| {pid} | `{name}` | {default} | {lo} | {hi} | {'yes' if writable else 'no'} "
               f"| {'yes' if safety else 'no'} |")
        assert row in DOC, row


def test_sram_table_and_total_are_documented():
    for name, size in sram.SRAM_LAYOUT.items():
        assert f"| `{name}` | {size} |" in DOC, name
    assert f"| **total** | **{sram.total_with_stack()}** of 4096 |" in DOC


def test_firmware_telemetry_struct_is_the_protocol_layout():
    msg = Telemetry(123, -5, 7, (1000, 1500, 2455, 673, 545, 2391), (300, 0xFFFF, 2, 3, 4),
                    0x1F, 1, 2, 3, 4)
    payload = TELEMETRY_STRUCT.pack(123, -5, 7, 1000, 1500, 2455, 673, 545, 2391,
                                    300, 0xFFFF, 2, 3, 4, 0x1F, 1, 2, 3, 4)
    assert payload == msg.encode()
