"""ARM920T cycle accounting: what each host stage would cost on the S3C2440 at 400 MHz.

Every kernel returns an :class:`OpCounts`; :func:`cycles` turns counts into ARM920T cycles with
the constants below, and the host's simulated clock advances by ``cycles / 400 MHz``. Wall-clock
time of the Python code never decides behaviour.

Sources for the constants (ARM920T Technical Reference Manual, ARM DDI 0151C, ch. 7 and 8;
S3C2440A user manual for FCLK/HCLK):
- data-processing instruction: 1 cycle; a load whose result is used by the next instruction
  adds 1 interlock cycle, so a pixel read costs ~2 cycles in a cached, unrolled loop;
- MUL/MLA with the 8-bit Booth multiplier: 2-5 cycles by operand size (we charge 3 for 16-bit
  operands, 5 for 32x32);
- no divide instruction: the EABI helper ``__aeabi_idiv`` takes 20-140 cycles (we charge 45);
- soft-float (no FPU): the host's float work is float64 (as the Python computes it), libgcc's
  double helpers: add/mul ~75 cycles, divide ~520, compare ~33 (measured, docs/budget.md);
- 16 KB D-cache with 32-byte lines; a line fill from SDRAM costs ~40 FCLK cycles at
  FCLK:HCLK = 4:1 (no public figure: the stated parameter of the calibration, docs/budget.md),
  one per 32 bytes streamed (frame buffers are read sequentially).

The counts of the front-end kernels (grey, dark threshold, labelling) and of the radial symbol
are calibrated against their C run as ARM920T code (``mobigrasp calibrate``, docs/budget.md).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

FCLK_HZ = 400_000_000

CYCLES_ALU = 1  # TRM 8.2: single-cycle data processing
CYCLES_BRANCH = 3  # taken branch refills the 5-stage pipeline (TRM 8.2)
CYCLES_PIXEL_READ = 2  # LDRB + load-use interlock (TRM 8.2)
CYCLES_PIXEL_WRITE = 1  # STRB into the write buffer
CYCLES_MUL = 3  # MUL, 16-bit operands, Booth early termination (TRM 8.2)
CYCLES_MUL32 = 5  # MUL/SMULL with full 32-bit operands
CYCLES_DIV = 45  # __aeabi_idiv, typical for 32/16-bit quotients (20-140)
CYCLES_LUT = 2  # LDR from a table in cache + interlock
CYCLES_FLOAT_OP = 75  # double add/mul, libgcc __aeabi_dadd ~95, __aeabi_dmul ~57 (calibrated)
CYCLES_FLOAT_DIV = 520  # double divide, libgcc __aeabi_ddiv 490-554 (calibrated)
CYCLES_FLOAT_CMP = 33  # double compare (__aeabi_cdcmple & co.), charged as ALU cycles
CYCLES_LINE_FILL = 40  # one 32-byte D-cache line from SDRAM (the calibration's parameter)
CACHE_LINE_BYTES = 32


@dataclass
class OpCounts:
    """Operation counts of one kernel call; add them up to cost a stage."""

    pixels_read: int = 0
    pixels_written: int = 0
    alu: int = 0
    branches: int = 0
    muls: int = 0
    muls32: int = 0
    divs: int = 0
    luts: int = 0
    float_ops: int = 0
    float_divs: int = 0
    bytes_streamed: int = 0  # bytes read once from SDRAM (frame buffers), for cache line fills

    def __add__(self, other: OpCounts) -> OpCounts:
        # Hot path (every kernel of every frame adds counts): field by field, not fields().
        return OpCounts(self.pixels_read + other.pixels_read,
                        self.pixels_written + other.pixels_written, self.alu + other.alu,
                        self.branches + other.branches, self.muls + other.muls,
                        self.muls32 + other.muls32, self.divs + other.divs,
                        self.luts + other.luts, self.float_ops + other.float_ops,
                        self.float_divs + other.float_divs,
                        self.bytes_streamed + other.bytes_streamed)

    def scaled(self, k: int) -> OpCounts:
        """The counts of ``k`` repetitions."""
        k = int(k)
        return OpCounts(*[a * k for a in self.as_tuple()])

    def as_tuple(self) -> tuple[int, ...]:
        """The counts in field order (what a copy is built from)."""
        return (self.pixels_read, self.pixels_written, self.alu, self.branches, self.muls,
                self.muls32, self.divs, self.luts, self.float_ops, self.float_divs,
                self.bytes_streamed)

    def cycles(self) -> int:
        """ARM920T cycles for these counts (constants above)."""
        return (
            self.pixels_read * CYCLES_PIXEL_READ
            + self.pixels_written * CYCLES_PIXEL_WRITE
            + self.alu * CYCLES_ALU
            + self.branches * CYCLES_BRANCH
            + self.muls * CYCLES_MUL
            + self.muls32 * CYCLES_MUL32
            + self.divs * CYCLES_DIV
            + self.luts * CYCLES_LUT
            + self.float_ops * CYCLES_FLOAT_OP
            + self.float_divs * CYCLES_FLOAT_DIV
            + -(-self.bytes_streamed // CACHE_LINE_BYTES) * CYCLES_LINE_FILL
        )

    def time_us(self) -> int:
        """Modelled ARM9 time in whole microseconds (rounded up) at FCLK = 400 MHz."""
        return -(-self.cycles() * 1_000_000 // FCLK_HZ)


# as_tuple() lists the fields by hand for speed; this keeps it honest if a field is added.
assert tuple(f.name for f in fields(OpCounts)) == (
    "pixels_read", "pixels_written", "alu", "branches", "muls", "muls32", "divs", "luts",
    "float_ops", "float_divs", "bytes_streamed"), "update OpCounts.as_tuple()"
