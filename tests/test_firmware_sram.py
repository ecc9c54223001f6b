"""Static memory budget: declared sizes sum (with the stack estimate) to at most 4096 bytes,
and the live firmware's buffers are the sizes the table declares."""

from mobigrasp.mcu_sim.firmware import sram
from mobigrasp.mcu_sim.firmware.params import PARAM_TABLE
from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.protocol import MAX_ENCODED, MAX_WIRE


def test_budget_fits_the_atmega128():
    total = sram.total_with_stack()
    assert total == sram.static_bytes() + sram.STACK_ESTIMATE_BYTES
    assert total <= sram.SRAM_BYTES == 4096
    assert all(isinstance(v, int) and v > 0 for v in sram.SRAM_LAYOUT.values())


def test_live_buffers_match_the_declared_sizes():
    mcu = Mcu()
    fw = mcu.firmware
    layout = sram.SRAM_LAYOUT
    assert len(fw.rx.buf) == fw.rx.size == layout["rx_ring.buf"]
    assert mcu.board.usart0.tx_capacity == layout["tx_ring.buf"]
    assert layout["tx_frame_buf"] == MAX_WIRE
    assert layout["parser.frame_buf"] == MAX_ENCODED
    assert fw.dup.window == layout["dup.seqs"]
    assert len(fw.params.values) == len(PARAM_TABLE) == sram.PARAMS
    assert layout["params.values"] == 4 * len(fw.params.values)
    for name in ("latched_q8", "pending_q8", "target_q8", "step_q8"):
        assert layout[f"servo.{name}"] == 4 * len(getattr(fw.servos, name))
    assert layout["sonar.range_mm"] == 2 * len(fw.sonar.range_mm)
    assert layout["enc_count"] == 4 * len(fw.enc_count)
