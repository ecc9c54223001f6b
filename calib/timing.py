"""A static timing model of the ARM9TDMI core of the ARM920T, applied to decoded basic blocks.

Cycle rules (ARM9TDMI TRM, ARM DDI 0145B, ch. 7 "Instruction cycle times"; the same table as
``get_insn_ticks_arm`` of the Android emulator's trace.c, which cites the ARM920T TRM):

- data processing 1 cycle, +1 with a register-specified shift; writing the PC 3 (a branch);
- MUL/MLA 2 + m, long multiplies (UMULL, SMULL, UMLAL, SMLAL) 3 + m, m = 1..4 the significant
  bytes of Rs (8-bit Booth steps; Rs is read when the instruction runs);
- LDR 1, +1 when the next instruction reads the loaded register; LDRB/LDRH/LDRSB/LDRSH +2 when
  the next reads it, +1 when the one after does; a load into the PC 5;
- LDM/STM max(2, n) for n registers, n + 4 with the PC; SWP 2;
- branches 1 not taken, 3 taken (the pipeline refill); a block is taken when the next block
  that runs does not start where it ends.

The interlocks are found inside each block in instruction order; a load whose user is in the next
block is not charged (a block ends in a branch, so this is a load just before it). The D-cache is
:class:`DCache`: 16 KB, 32-byte lines, 64-way (8 sets), allocate on read miss with round-robin
replacement, writes through the write buffer without allocation (no write stalls modelled).
A read miss costs ``line_fill_cycles``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import capstone
from capstone import arm as A

LINE_BYTES = 32
D_CACHE_BYTES = 16 * 1024
D_CACHE_WAYS = 64
LINE_FILL_CYCLES = 40  # no public figure: about 40-50 core cycles at FCLK:HCLK = 4:1

_BYTE_LOADS = {A.ARM_INS_LDRB, A.ARM_INS_LDRH, A.ARM_INS_LDRSB, A.ARM_INS_LDRSH,
               A.ARM_INS_LDRBT}
_WORD_LOADS = {A.ARM_INS_LDR, A.ARM_INS_LDRT, A.ARM_INS_LDRD}
_MULS = {A.ARM_INS_MUL, A.ARM_INS_MLA}
_LONG_MULS = {A.ARM_INS_UMULL, A.ARM_INS_SMULL, A.ARM_INS_UMLAL, A.ARM_INS_SMLAL}
_BLOCK_MEM = {A.ARM_INS_LDM, A.ARM_INS_LDMDA, A.ARM_INS_LDMDB, A.ARM_INS_LDMIB,
              A.ARM_INS_STM, A.ARM_INS_STMDA, A.ARM_INS_STMDB, A.ARM_INS_STMIB,
              A.ARM_INS_PUSH, A.ARM_INS_POP}
_BRANCHES = {A.ARM_INS_B, A.ARM_INS_BL, A.ARM_INS_BX, A.ARM_INS_BLX}
_REG_SHIFTS = {A.ARM_SFT_ASR_REG, A.ARM_SFT_LSL_REG, A.ARM_SFT_LSR_REG, A.ARM_SFT_ROR_REG,
               A.ARM_SFT_RRX_REG}
CLASSES = ("alu", "mul", "load", "store", "ldm_stm", "branch", "other")


@dataclass
class Block:
    """One decoded block: its static cycles (branch not taken), instruction count, class mix,
    interlock cycles, and the multiplies whose Rs decides their time (address, Rs register)."""

    n_insns: int
    cycles: int
    interlock: int
    mix: dict[str, int]
    muls: list[tuple[int, int]] = field(default_factory=list)


def _reads(insn) -> set[int]:
    return set(insn.regs_access()[0])


def _loaded_reg(insn) -> int | None:
    ops = insn.operands
    return ops[0].reg if ops and ops[0].type == A.ARM_OP_REG else None


def classify(insn) -> tuple[str, int]:
    """(class, static cycles without interlocks; multiplies without their m)."""
    i = insn.id
    ops = insn.operands
    writes_pc = A.ARM_REG_PC in insn.regs_access()[1]
    if i in _BRANCHES:
        return "branch", 1
    if i in _BLOCK_MEM:
        n = sum(1 for o in ops if o.type == A.ARM_OP_REG) - (0 if i in (A.ARM_INS_PUSH,
                                                                          A.ARM_INS_POP) else 1)
        has_pc = any(o.type == A.ARM_OP_REG and o.reg == A.ARM_REG_PC for o in ops)
        return "ldm_stm", n + 4 if has_pc else max(2, n)
    if i in _BYTE_LOADS or i in _WORD_LOADS:
        return "load", 5 if writes_pc else 1
    if insn.mnemonic.startswith("str"):
        return "store", 1
    if i in _MULS:
        return "mul", 2
    if i in _LONG_MULS:
        return "mul", 3
    if i == A.ARM_INS_SWP or i == A.ARM_INS_SWPB:
        return "other", 2
    if insn.group(A.ARM_GRP_INT) or insn.id in (A.ARM_INS_MRS, A.ARM_INS_MSR):
        return "other", 1
    extra = 1 if any(o.shift.type in _REG_SHIFTS for o in ops) else 0
    return "alu", (3 if writes_pc else 1) + extra


class Decoder:
    """Capstone in ARM mode with details, and the block analysis of :func:`analyse`."""

    def __init__(self) -> None:
        self.cs = capstone.Cs(capstone.CS_ARCH_ARM, capstone.CS_MODE_ARM)
        self.cs.detail = True

    def analyse(self, code: bytes, address: int) -> Block:
        insns = list(self.cs.disasm(code, address))
        mix = dict.fromkeys(CLASSES, 0)
        cycles = interlock = 0
        muls = []
        reads = [_reads(x) for x in insns]
        for k, insn in enumerate(insns):
            cls, cyc = classify(insn)
            mix[cls] += 1
            cycles += cyc
            if insn.id in _MULS or insn.id in _LONG_MULS:
                rs = insn.operands[2].reg if insn.id in _MULS or len(insn.operands) < 4 \
                    else insn.operands[3].reg
                muls.append((insn.address, rs))
            if cls == "load" and cyc == 1:
                rd = _loaded_reg(insn)
                if rd is None:
                    continue
                if k + 1 < len(insns) and rd in reads[k + 1]:
                    interlock += 2 if insn.id in _BYTE_LOADS else 1
                elif insn.id in _BYTE_LOADS and k + 2 < len(insns) and rd in reads[k + 2]:
                    interlock += 1
        return Block(len(insns), cycles + interlock, interlock, mix, muls)


def booth_m(rs_value: int) -> int:
    """Booth steps of a multiply: 1..4 by the significant bytes of Rs (all ones above count as
    not significant, as for small negative values)."""
    v = rs_value & 0xFFFFFFFF
    for m, lim in ((1, 8), (2, 16), (3, 24)):
        top = v >> lim
        if top == 0 or top == (0xFFFFFFFF >> lim):
            return m
    return 4


class DCache:
    """16 KB, 32-byte lines, 64-way set-associative data cache with round-robin replacement,
    allocating on read misses only."""

    def __init__(self, size: int = D_CACHE_BYTES, ways: int = D_CACHE_WAYS,
                 line: int = LINE_BYTES) -> None:
        self.sets = size // (ways * line)
        self.ways = ways
        self.shift = line.bit_length() - 1
        self.lines: list[dict[int, int]] = [{} for _ in range(self.sets)]
        self.slots: list[list[int | None]] = [[None] * ways for _ in range(self.sets)]
        self.next_way = [0] * self.sets
        self.misses = 0
        self.reads = 0

    def read(self, address: int, size: int) -> int:
        """Misses of one read of ``size`` bytes (a word read never spans two lines)."""
        self.reads += 1
        tag = address >> self.shift
        s = tag % self.sets
        present = self.lines[s]
        if tag in present:
            return 0
        way = self.next_way[s]
        old = self.slots[s][way]
        if old is not None:
            del present[old]
        self.slots[s][way] = tag
        present[tag] = way
        self.next_way[s] = (way + 1) % self.ways
        self.misses += 1
        return 1

    def flush(self) -> None:
        """Invalidate every line (a new frame's buffers are not in the cache)."""
        for d in self.lines:
            d.clear()
        self.slots = [[None] * self.ways for _ in range(self.sets)]
        self.next_way = [0] * self.sets
