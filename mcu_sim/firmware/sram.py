"""Static SRAM budget of the firmware, as ``avr-size`` would report it for the C port.

Every global buffer and state variable of the program has a row here with its size in bytes in
C (``uint8_t`` 1, ``int16_t`` 2, ``int32_t`` 4); the Python modules size their buffers from these
constants, and tests check the live objects against the table. The ATmega128 has 4096 bytes of
SRAM; what is left after ``.data`` + ``.bss`` must hold the stack, whose worst case is estimated
below from the deepest call chain (main loop -> frame dispatch -> telemetry encode -> COBS) plus
the largest interrupt frame nested on top of it.
"""

from __future__ import annotations

SRAM_BYTES = 4096
RX_RING_BYTES = 128  # USART0 RX ring: 10.9 ms of line traffic at 117647 baud
TX_RING_BYTES = 128  # USART0 TX ring: two telemetry frames
MAX_WIRE_BYTES = 71  # protocol MAX_WIRE: COBS(3 + 64 + 2) + delimiter
MAX_RAW_BYTES = 69  # decoded frame: version, seq, type, 64 payload, CRC
DUP_WINDOW = 64  # sequence numbers remembered by the duplicate filter (docs/protocol.md §5.2)
SERVOS = 6
SONARS = 5
PARAMS = 20

SRAM_LAYOUT: dict[str, int] = {
    "rx_ring.buf": RX_RING_BYTES,
    "rx_ring.head_tail_overruns": 1 + 1 + 2,
    "tx_ring.buf": TX_RING_BYTES,
    "tx_ring.head_tail": 2,
    "parser.frame_buf": MAX_WIRE_BYTES - 1,  # bytes up to the delimiter
    "parser.len_state": 2,
    "parser.decoded": MAX_RAW_BYTES,
    "parser.counters": 7 * 2,
    "tx_frame_buf": MAX_WIRE_BYTES,
    "tx_seq": 1,
    "dup.seqs": DUP_WINDOW,
    "dup.crcs": 2 * DUP_WINDOW,
    "dup.results": DUP_WINDOW,
    "dup.newest": 2,
    "servo.latched_q8": SERVOS * 4,
    "servo.pending_q8": SERVOS * 4,
    "servo.target_q8": SERVOS * 4,
    "servo.step_q8": SERVOS * 4,
    "servo.min_max_us": SERVOS * 2 * 2,
    "params.values": PARAMS * 4,
    "wheels.target_mmps": 2 * 2,
    "wheels.target_q8": 2 * 4,
    "wheels.integral": 2 * 4,
    "wheels.last_count": 2 * 4,
    "wheels.duty": 2 * 2,
    "wheels.duty_out": 2 * 2,  # last duty written to OCR0/OCR2, to skip rewrites
    "enc_count": 2 * 4,
    "sonar.range_mm": SONARS * 2,
    "sonar.slot_state": 1 + 4 + 4 + 1 + 1 + 4,
    "timebase.overflows": 4,
    "schedule.next_us": 3 * 4,
    "watchdog.last_valid_us": 4,
    "flags": 6,
    "counters": 7 * 2,
    "libc_and_vectors": 64,  # avr-libc globals, __malloc vars (unused), reserve
}
# Deepest chain: main (8) -> loop (24) -> handle frame (32) -> send telemetry (48, a 44-byte
# payload is built in tx_frame_buf, not on the stack) -> encode/COBS/CRC (24), plus the RX ISR
# saving 32 registers + SREG + return address (35) and a nested timer ISR (35); rounded up to a
# generous 512 bytes because avr-gcc call frames are hard to bound exactly.
STACK_ESTIMATE_BYTES = 512


def static_bytes() -> int:
    """Sum of the table (.data + .bss)."""
    return sum(SRAM_LAYOUT.values())


def total_with_stack() -> int:
    """Static bytes plus the stack estimate; must stay within SRAM_BYTES."""
    return static_bytes() + STACK_ESTIMATE_BYTES
