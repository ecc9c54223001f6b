"""SRAM budget: the C port's .data + .bss and worst-case stack (generated from the ELF into
sram.py) fit the ATmega128's 4096 bytes, and the buffers both ports share have the sizes the C
symbols have."""

from dataclasses import fields

from mobigrasp.mcu_sim.firmware import sram
from mobigrasp.mcu_sim.firmware.params import PARAM_TABLE
from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.protocol import MAX_ENCODED, MAX_WIRE, ParserStats


def test_budget_fits_the_atmega128():
    assert sum(sram.SRAM_LAYOUT.values()) == sram.static_bytes() == sram.DATA_BSS_BYTES
    assert sram.stack_bytes() == sram.STACK_MAIN_BYTES + sram.STACK_ISR_BYTES > 0
    assert sram.total_with_stack() == sram.static_bytes() + sram.stack_bytes()
    assert sram.total_with_stack() <= sram.SRAM_BYTES == 4096
    assert sram.FLASH_BYTES_USED <= 128 * 1024


def test_live_buffers_match_the_c_symbols():
    mcu = Mcu()
    fw = mcu.firmware
    layout = sram.SRAM_LAYOUT
    # byte_ring_t: buf, head, tail, uint32 overruns
    assert len(fw.rx.buf) == fw.rx.size == sram.RX_RING_BYTES == layout["fw_rx"] - 1 - 1 - 4
    assert mcu.board.usart0.tx_capacity == sram.TX_RING_BYTES == layout["tx_ring"]
    assert layout["tx_buf"] == MAX_WIRE
    # frame_parser_t: encoded bytes, len, skipping, ring start, one uint32 per ParserStats field
    assert layout["fw_parser"] == MAX_ENCODED + 3 + 4 * len(fields(ParserStats))
    # dup_filter_t: seq tags, uint16 CRCs, answers, int16 newest, two uint32 counters
    assert fw.dup.window == sram.DUP_WINDOW and layout["fw_dup"] == sram.DUP_WINDOW * 4 + 2 + 8
    assert len(fw.params.values) == len(PARAM_TABLE) == sram.PARAMS
    assert layout["params_values"] == 4 * len(fw.params.values)
    # servo_bank_t: four int32 arrays and two int16 arrays of six channels
    assert layout["fw_servos"] == sum(4 * len(getattr(fw.servos, n)) for n in
                                      ("latched_q8", "pending_q8", "target_q8", "step_q8")) \
        + 2 * len(fw.servos.min_us) + 2 * len(fw.servos.max_us)
    assert layout["fw_enc_count"] == 4 * len(fw.enc_count)
