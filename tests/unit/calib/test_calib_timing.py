"""The static ARM9TDMI timing rules and the D-cache model on hand-encoded instructions."""

import struct

import pytest

from mobigrasp.calib import timing

LDRB_R3_R0 = 0xE5D03000  # ldrb r3, [r0]
LDR_R3_R0 = 0xE5903000  # ldr r3, [r0]
ADD_R3_1 = 0xE2833001  # add r3, r3, #1
ADD_R1_1 = 0xE2811001  # add r1, r1, #1
ADD_REG_SHIFT = 0xE0810312  # add r0, r1, r2, lsl r3
MUL_R0_R1_R2 = 0xE0000291  # mul r0, r1, r2
POP_R4_PC = 0xE8BD8010  # pop {r4, pc}
B_BACK = 0xEAFFFFFE  # b . (a branch: 1 cycle statically, the taken 2 are dynamic)


def _block(*words):
    return timing.Decoder().analyse(struct.pack(f"<{len(words)}I", *words), 0x1000)


@pytest.mark.parametrize("words,cycles,interlock", [
    ((LDRB_R3_R0, ADD_R3_1), 4, 2),  # byte load used next: 2-cycle interlock
    ((LDRB_R3_R0, ADD_R1_1, ADD_R3_1), 4, 1),  # used by the one after: 1
    ((LDR_R3_R0, ADD_R3_1), 3, 1),  # word load used next: 1
    ((LDR_R3_R0, ADD_R1_1, ADD_R3_1), 3, 0),  # word load used after one: none
    ((ADD_REG_SHIFT,), 2, 0),  # register-specified shift
    ((MUL_R0_R1_R2,), 2, 0),  # MUL without its Booth steps (added when it runs)
    ((POP_R4_PC,), 6, 0),  # LDM with the PC: n + 4
    ((B_BACK,), 1, 0),
])
def test_block_cycles(words, cycles, interlock):
    blk = _block(*words)
    assert blk.n_insns == len(words)
    assert (blk.cycles, blk.interlock) == (cycles, interlock)


def test_multiplies_are_listed_with_their_rs():
    blk = _block(MUL_R0_R1_R2)
    assert blk.mix["mul"] == 1 and len(blk.muls) == 1


@pytest.mark.parametrize("rs,m", [(0, 1), (0xFF, 1), (0x100, 2), (0xFFFF, 2), (0x1_0000, 3),
                                  (0x100_0000, 4), (0xFFFFFFFF, 1), (0xFFFF_FF00, 1),
                                  (0xFFFF_0000, 2)])
def test_booth_steps(rs, m):
    assert timing.booth_m(rs) == m


def test_dcache_streams_one_miss_per_line_and_keeps_what_fits():
    c = timing.DCache()
    assert sum(c.read(a, 1) for a in range(0, 8192)) == 8192 // 32
    assert sum(c.read(a, 4) for a in range(0, 8192, 4)) == 0  # 8 KB fits in 16 KB
    c.flush()
    assert sum(c.read(a, 4) for a in range(0, 20480, 4)) == 640
    # 20 KB does not fit: round robin evicts the oldest lines, a second pass misses again
    assert sum(c.read(a, 4) for a in range(0, 20480, 4)) == 640
