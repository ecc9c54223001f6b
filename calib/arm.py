"""The hostc/ kernels as ARM920T code: built with arm-none-eabi-gcc, run under unicorn.

``build()`` compiles the same C as calib/native.py with ``-mcpu=arm920t -marm -O2
-ffreestanding -nostdlib`` (libgcc for the division and soft-float helpers) into a flat image at
``CODE_BASE`` and reads the symbol addresses; the toolchain (Debian's ``gcc-arm-none-eabi``) is
installed with apt-get when it is missing. :class:`Arm9` maps the image, the buffers and a
stack into unicorn (CPU model ARM926: the same ARMv4T/v5 user instructions, there is no 920T),
calls one kernel per :meth:`Arm9.call` and times it with calib/timing.py: a block hook adds each
executed block's static cycles (and 2 when it ends in a taken branch), a code hook on each
multiply adds its Booth steps from Rs, a read hook runs the D-cache model.
"""

from __future__ import annotations

import shutil
import struct
import subprocess
import sys
from dataclasses import dataclass, field

import numpy as np

from mobigrasp.calib import native, timing

CC = "arm-none-eabi-gcc"
CFLAGS = ["-mcpu=arm920t", "-marm", "-O2", "-ffreestanding", "-nostdlib", "-std=c99"]
CODE_BASE = 0x0001_0000
CODE_SIZE = 0x0001_0000
DATA_BASE = 0x0010_0000
DATA_SIZE = 0x0080_0000
STACK_TOP = 0x0100_0000
STACK_SIZE = 0x0001_0000
STOP = 0x0000_1000  # the return address of every call: a page of its own


class ToolchainError(RuntimeError):
    """The ARM toolchain is missing and could not be installed, or a build failed."""


def ensure_toolchain(progress=None) -> str:
    """Path of arm-none-eabi-gcc, installing Debian's gcc-arm-none-eabi when it is missing."""
    path = shutil.which(CC)
    if path:
        return path
    if shutil.which("apt-get") is None:
        raise ToolchainError(f"{CC} not found and no apt-get to install gcc-arm-none-eabi")
    for argv in (["apt-get", "install", "-y", "gcc-arm-none-eabi"], ["apt-get", "update"],
                 ["apt-get", "install", "-y", "gcc-arm-none-eabi"]):
        if progress:
            progress(f"installing the ARM toolchain: {' '.join(argv)}")
        r = subprocess.run(argv, capture_output=True, text=True)
        if r.returncode == 0 and shutil.which(CC):
            return shutil.which(CC)
    raise ToolchainError(f"{CC} not found and apt-get could not install gcc-arm-none-eabi")


@dataclass(frozen=True)
class Image:
    """A flat ARM image at CODE_BASE and its function symbols."""

    code: bytes
    symbols: dict[str, int]


def build(progress=None) -> Image:
    """Compile and link hostc/ for the ARM920T (cached by the sources' hash)."""
    out = native.cache_dir() / f"arm-{native.source_hash()}"
    binf, symf = out / "kernels.bin", out / "kernels.sym"
    if not (binf.is_file() and symf.is_file()):
        cc = ensure_toolchain(progress)
        out.mkdir(parents=True, exist_ok=True)
        elf = out / "kernels.elf"
        srcs = [str(native.HOSTC / s) for s in native.SOURCES]
        r = subprocess.run([cc, *CFLAGS, f"-I{native.HOSTC}", f"-Wl,-Ttext={CODE_BASE:#x}",
                            "-Wl,--entry=0", "-o", str(elf), *srcs, "-lgcc"],
                           capture_output=True, text=True)
        if r.returncode != 0:
            raise ToolchainError(f"{CC} failed: {r.stderr.strip().splitlines()[-1:]}")
        prefix = cc[:-3]
        subprocess.run([prefix + "objcopy", "-O", "binary", str(elf), str(binf)], check=True)
        nm = subprocess.run([prefix + "nm", str(elf)], capture_output=True, text=True,
                            check=True).stdout
        symf.write_text(nm)
    syms = {}
    for line in symf.read_text().splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[1] in "tT":
            syms[parts[2]] = int(parts[0], 16)
    code = binf.read_bytes()
    if len(code) > CODE_SIZE:
        raise ToolchainError(f"ARM image of {len(code)} bytes does not fit {CODE_SIZE}")
    return Image(code, syms)


@dataclass
class Timing:
    """What one call cost under the model."""

    instructions: int = 0
    cycles: int = 0  # including the line fills
    interlock_cycles: int = 0
    taken_branches: int = 0
    mul_cycles: int = 0
    reads: int = 0
    read_misses: int = 0
    fill_cycles: int = 0
    mix: dict[str, int] = field(default_factory=lambda: dict.fromkeys(timing.CLASSES, 0))

    @classmethod
    def sum(cls, *parts: Timing) -> Timing:
        """The timing of calls run one after the other."""
        out = cls()
        for p in parts:
            for f in ("instructions", "cycles", "interlock_cycles", "taken_branches",
                      "mul_cycles", "reads", "read_misses", "fill_cycles"):
                setattr(out, f, getattr(out, f) + getattr(p, f))
            for k, v in p.mix.items():
                out.mix[k] += v
        return out

    @property
    def cpi(self) -> float:
        """Cycles per instruction."""
        return self.cycles / self.instructions if self.instructions else 0.0


class Arm9:
    """One emulated ARM920T with the kernels loaded; :meth:`call` runs one kernel."""

    def __init__(self, image: Image, line_fill_cycles: int = timing.LINE_FILL_CYCLES) -> None:
        from unicorn import UC_HOOK_BLOCK, UC_HOOK_MEM_READ

        self.image = image
        self.line_fill_cycles = int(line_fill_cycles)
        self.stack_top = STACK_TOP
        uc = new_uc()
        cached = self._map(uc)
        self.uc = uc
        self.decoder = timing.Decoder()
        self.blocks: dict[int, timing.Block] = {}
        self.cache = timing.DCache()
        self._t = Timing()
        self._prev_end = None
        uc.hook_add(UC_HOOK_BLOCK, self._on_block)
        uc.hook_add(UC_HOOK_MEM_READ, self._on_read, begin=cached[0], end=cached[1])
        self._mul_hooked: set[int] = set()

    def _map(self, uc) -> tuple[int, int]:
        """Map the image, the data area and the stack into ``uc``; returns the first and last
        address the D-cache model sees reads of (the data and the stack, not the image)."""
        uc.mem_map(STOP, 0x1000)
        uc.mem_map(CODE_BASE, CODE_SIZE)
        uc.mem_write(CODE_BASE, self.image.code)
        uc.mem_map(DATA_BASE, DATA_SIZE)
        uc.mem_map(STACK_TOP - STACK_SIZE, STACK_SIZE)
        return DATA_BASE, STACK_TOP - 1

    def _on_block(self, uc, address, size, _user):
        blk = self.blocks.get(address)
        if blk is None:
            blk = self.decoder.analyse(bytes(uc.mem_read(address, size)), address)
            self.blocks[address] = blk
            self._hook_muls(blk, address, size)
        t = self._t
        if self._prev_end is not None and address != self._prev_end:
            t.cycles += 2
            t.taken_branches += 1
        self._prev_end = address + size
        t.instructions += blk.n_insns
        t.cycles += blk.cycles
        t.interlock_cycles += blk.interlock
        for k, v in blk.mix.items():
            t.mix[k] += v

    def _hook_muls(self, blk: timing.Block, address: int, size: int) -> None:
        """A code hook on each multiply of a block seen for the first time. The block was
        translated before its hooks existed, so its translation is dropped: the next run of it
        is translated again with them (this run's multiplies go without their m)."""
        from unicorn import UC_HOOK_CODE

        from mobigrasp.calib.unicorn_regs import uc_reg

        if blk.muls:
            self.uc.ctl_remove_cache(address, address + size)
        for addr, rs in blk.muls:
            if addr in self._mul_hooked:
                continue
            self._mul_hooked.add(addr)
            reg = uc_reg(rs)

            def on_mul(uc, _a, _s, _u, reg=reg):
                m = timing.booth_m(uc.reg_read(reg))
                self._t.cycles += m
                self._t.mul_cycles += m
            self.uc.hook_add(UC_HOOK_CODE, on_mul, begin=addr, end=addr)

    def _on_read(self, uc, _access, address, size, _value, _user):
        t = self._t
        t.reads += 1
        if self.cache.read(address, size):
            t.read_misses += 1
            t.fill_cycles += self.line_fill_cycles
            t.cycles += self.line_fill_cycles

    def write(self, offset: int, data) -> int:
        """Copy bytes into the data area at ``offset``; returns the address."""
        self.uc.mem_write(DATA_BASE + offset, bytes(data))
        return DATA_BASE + offset

    def read(self, address: int, nbytes: int) -> bytes:
        """Bytes from the emulated memory."""
        return bytes(self.uc.mem_read(address, nbytes))

    def call(self, symbol: str, *args: int | I64, cold: bool = True) -> tuple[int, Timing]:
        """Call ``symbol(args...)`` (AAPCS: r0-r3, the rest on the stack; an :class:`I64`
        argument takes an even register pair or 8 aligned stack bytes), from a cold D-cache
        unless ``cold`` is False (the cache as the previous call left it); returns r0 and the
        call's timing."""
        from unicorn.arm_const import UC_ARM_REG_R0

        if cold:
            self.cache.flush()
        self._t = Timing()
        self._prev_end = None
        run(self.uc, self.image.symbols[symbol], args, self.stack_top)
        r0 = self.uc.reg_read(UC_ARM_REG_R0)
        return r0 - (1 << 32) if r0 & 0x8000_0000 else r0, self._t


@dataclass(frozen=True)
class I64:
    """A 64-bit argument of :meth:`Arm9.call` (int64_t, AAPCS)."""

    value: int


def new_uc():
    """A unicorn ARM core of the ARM920T's instruction set (the ARM926 model: there is no 920T)."""
    from unicorn import UC_ARCH_ARM, UC_MODE_ARM, Uc
    from unicorn.arm_const import UC_CPU_ARM_926

    uc = Uc(UC_ARCH_ARM, UC_MODE_ARM)
    uc.ctl_set_cpu_model(UC_CPU_ARM_926)
    return uc


def run(uc, entry: int, args, stack_top: int) -> None:
    """Run the function at ``entry`` with ``args`` (ints, :class:`I64`) on ``uc`` until it
    returns to :data:`STOP` (AAPCS: the core registers r0-r3 in order, a 64-bit value in an
    even pair; what does not fit goes on the stack, 64-bit values 8-aligned)."""
    from unicorn.arm_const import UC_ARM_REG_LR, UC_ARM_REG_R0, UC_ARM_REG_SP

    regs: list[int | None] = [None] * 4
    stack = bytearray()
    ncrn = 0
    for a in args:
        if isinstance(a, I64):
            v = a.value & 0xFFFF_FFFF_FFFF_FFFF
            ncrn += ncrn % 2
            if ncrn <= 2:
                regs[ncrn], regs[ncrn + 1] = v & 0xFFFF_FFFF, v >> 32
                ncrn += 2
            else:
                ncrn = 4
                stack += bytes(len(stack) % 8) + v.to_bytes(8, "little")
        elif ncrn < 4:
            regs[ncrn] = int(a) & 0xFFFF_FFFF
            ncrn += 1
        else:
            stack += (int(a) & 0xFFFF_FFFF).to_bytes(4, "little")
    sp = stack_top - 64
    sp -= len(stack) + (len(stack) % 8)
    if stack:
        uc.mem_write(sp, bytes(stack))
    for k, v in enumerate(regs):
        if v is not None:
            uc.reg_write(UC_ARM_REG_R0 + k, v)
    uc.reg_write(UC_ARM_REG_SP, sp)
    uc.reg_write(UC_ARM_REG_LR, STOP)
    uc.emu_start(entry, STOP)


class FrontEnd:
    """The 000 kernels on the emulated ARM920T: grey, dark mask, labelling of one frame and the
    detectors after them, each with its result (read back, to check it against the Python
    kernels) and its timing."""

    RGB, GREY, MASK, HIST = 0x0, 0x4_0000, 0x6_0000, 0x7_0000
    LABELS, BLOCKS, PARENT, STATS = 0x8_0000, 0x18_0000, 0x1C_0000, 0x20_0000
    OUT, SCRATCH = 0x27_F000, 0x28_0000

    def __init__(self, arm: Arm9) -> None:
        self.arm = arm
        self._shape: tuple[int, int] | None = None
        self._n_lab = 0

    def run(self, rgb: np.ndarray, upto: str = "labelling") -> dict[str, tuple[object, Timing]]:
        """Stage name -> (result, timing) for one frame, the stages up to ``upto`` ("grey"
        or "labelling"); the grey image and the stats stay in memory for the detectors. The
        D-cache is cold when the frame arrives (a new DMA buffer); each later stage and
        detector finds it as the one before left it, as on the board."""
        a, base = self.arm, DATA_BASE
        h, w = rgb.shape[:2]
        n = h * w
        self._shape = (h, w)
        a.write(self.RGB, np.ascontiguousarray(rgb).tobytes())
        _, t_grey = a.call("mg_grey", base + self.RGB, base + self.GREY, n)
        grey = np.frombuffer(a.read(base + self.GREY, n), np.uint8).reshape(h, w)
        out: dict[str, tuple[object, Timing]] = {"grey": (grey, t_grey)}
        if upto == "grey":
            return out
        thr, t_dark = a.call("mg_dark_mask", base + self.GREY, base + self.MASK, n,
                             base + self.HIST, cold=False)
        mask = np.frombuffer(a.read(base + self.MASK, n), np.uint8).reshape(h, w)
        n_lab, t_lab = a.call("mg_label", base + self.MASK, w, h, base + self.LABELS,
                              base + self.BLOCKS, base + self.PARENT, base + self.STATS,
                              cold=False)
        labels = np.frombuffer(a.read(base + self.LABELS, 4 * n), np.int32).reshape(h, w)
        stats = np.frombuffer(a.read(base + self.STATS, 20 * n_lab), np.int32).reshape(n_lab, 5)
        self._n_lab = n_lab
        out["dark_threshold"] = ((mask, thr), t_dark)
        out["labelling"] = ((n_lab, labels, stats), t_lab)
        return out

    def _rgb_kernel(self, name: str, rgb: np.ndarray, n_out: int
                    ) -> tuple[tuple[int, ...] | None, Timing]:
        """A red detector on a frame that has just arrived (cold D-cache)."""
        a, base = self.arm, DATA_BASE
        h, w = rgb.shape[:2]
        a.write(self.RGB, np.ascontiguousarray(rgb).tobytes())
        found, t = a.call(name, base + self.RGB, w, h, base + self.SCRATCH, base + self.OUT, 0)
        res = struct.unpack(f"<{n_out}i", a.read(base + self.OUT, 4 * n_out)) if found else None
        return res, t

    def red_cylinder(self, rgb: np.ndarray) -> tuple[tuple[int, ...] | None, Timing]:
        """The 002 red cylinder on a frame that has just arrived (cold D-cache)."""
        return self._rgb_kernel("mg_red_cylinder", rgb, 10)

    def red_roi(self, rgb: np.ndarray) -> tuple[tuple[int, ...] | None, Timing]:
        """The 002 colour ROI alone on a frame that has just arrived (cold D-cache)."""
        return self._rgb_kernel("mg_red_roi", rgb, 8)

    def load(self, grey: np.ndarray, stats: np.ndarray) -> None:
        """Put a front end's grey image and stats in memory (instead of :meth:`run`)."""
        self._shape = grey.shape
        self._n_lab = len(stats)
        self.arm.write(self.GREY, np.ascontiguousarray(grey).tobytes())
        self.arm.write(self.STATS, np.ascontiguousarray(stats, np.int32).tobytes())

    def radial_symbol(self, f_px: int, u0_px: int, v0_px: int
                      ) -> tuple[tuple[int, ...] | None, Timing]:
        """The radial symbol on the frame of the last :meth:`run` (its grey and stats)."""
        a, base = self.arm, DATA_BASE
        h, w = self._shape
        found, t = a.call("mg_radial_symbol", base + self.GREY, w, h, base + self.STATS,
                          self._n_lab, f_px, u0_px, v0_px, base + self.SCRATCH, base + self.OUT,
                          0, cold=False)
        res = struct.unpack("<6i", a.read(base + self.OUT, 24)) if found else None
        return res, t


    def radial_cut(self) -> tuple[tuple[int, ...] | None, Timing]:
        """The radial symbol cut by the frame's border from the stats of the last :meth:`run`:
        (x, y, w, h, side) or None."""
        a, base = self.arm, DATA_BASE
        h, w = self._shape
        found, t = a.call("mg_radial_cut", base + self.STATS, self._n_lab, w, h,
                          base + self.OUT, 0, cold=False)
        res = struct.unpack("<5i", a.read(base + self.OUT, 20)) if found else None
        return res, t

    def dual_plus(self, alpha_mrad: int, f_px: int, u0_px: int
                  ) -> tuple[tuple[int, ...] | None, Timing]:
        """The dual "+" on the frame of the last :meth:`run` (its grey, labels and stats)."""
        a, base = self.arm, DATA_BASE
        h, w = self._shape
        found, t = a.call("mg_dual_plus", base + self.GREY, base + self.LABELS, w, h,
                          base + self.STATS, self._n_lab, alpha_mrad, f_px, u0_px,
                          base + self.SCRATCH, base + self.OUT, 0, cold=False)
        res = struct.unpack("<11i", a.read(base + self.OUT, 44)) if found else None
        return res, t


    def spoke(self) -> tuple[tuple | None, Timing]:
        """The spoke on the frame of the last :meth:`run` (its grey, labels and stats)."""
        a, base = self.arm, DATA_BASE
        h, w = self._shape
        found, t = a.call("mg_spoke", base + self.GREY, base + self.LABELS, w, h,
                          base + self.STATS, self._n_lab, base + self.SCRATCH, base + self.OUT,
                          0, cold=False)
        res = native.spoke_tuple(struct.unpack("<26i", a.read(base + self.OUT, 104))) \
            if found else None
        return res, t


    def double_cross(self, yaw_mrad: int, pitch_mrad: int, f_px: int
                     ) -> tuple[tuple | None, Timing]:
        """The 002 double cross on the grey image of the last :meth:`run`."""
        a, base = self.arm, DATA_BASE
        h, w = self._shape
        found, t = a.call("mg_double_cross", base + self.GREY, w, h, yaw_mrad, pitch_mrad, f_px,
                          base + self.SCRATCH, base + self.OUT, 0, cold=False)
        res = native.double_cross_tuple(struct.unpack("<10i", a.read(base + self.OUT, 40))) \
            if found else None
        return res, t

    def locate_ring_pair(self, d_pixel_q4: int, u_q4: int, v_q4: int, width_q4: int,
                         alpha_mrad: int, theta5_mrad: int, f_px: int, u0_px: int, v0_px: int,
                         d_um: int) -> tuple[tuple[int, ...] | None, Timing]:
        """The 002 ring-pair ranging after a red cylinder result (the cache as it left it)."""
        a, base = self.arm, DATA_BASE
        ok, t = a.call("mg_locate_ring_pair", d_pixel_q4, u_q4, v_q4, width_q4, alpha_mrad,
                       theta5_mrad, f_px, u0_px, v0_px, d_um, base + self.OUT, cold=False)
        res = struct.unpack("<6i", a.read(base + self.OUT, 24)) if ok else None
        return res, t


def progress_stderr(msg: str) -> None:
    """Progress line on stderr."""
    print(msg, file=sys.stderr, flush=True)


class Planner:
    """The Bezier candidate evaluation of 000 and 001 on the emulated ARM920T (fixed point,
    host/planning/bezier_q.py), each call's result read back with its timing. A plan runs in a
    control step, after vision has had the D-cache: each call starts cold."""

    CTRL, LIM, GEO, REASON, FIRST, COST, TRIED, STATE = (
        0x40_0000, 0x4F_0000, 0x4F_1000, 0x50_0000, 0x51_0000, 0x52_0000, 0x53_0000, 0x53_0010)

    def __init__(self, arm: Arm9) -> None:
        self.arm = arm

    def _put(self, ctrl, lim, geo=None) -> int:
        a = self.arm
        ctrl = np.ascontiguousarray(ctrl, np.int32)
        if ctrl.nbytes > self.LIM - self.CTRL or (geo is not None and geo.size * 8 > 0xF000):
            raise ValueError(f"candidate set of {ctrl.shape[0]} curves does not fit the image")
        a.write(self.CTRL, ctrl.tobytes())
        a.write(self.LIM, np.ascontiguousarray(lim, np.int32).tobytes())
        if geo is not None:
            a.write(self.GEO, np.ascontiguousarray(geo, np.int64).tobytes())
        return ctrl.shape[0]

    def _out(self, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        a, base = self.arm, DATA_BASE
        return (np.frombuffer(a.read(base + self.REASON, 4 * m), np.int32),
                np.frombuffer(a.read(base + self.FIRST, 4 * m), np.int32),
                np.frombuffer(a.read(base + self.COST, 8 * m), np.int64))

    def bezier000(self, ctrl, n: int, lim, k1_q16: int, k2_q16: int):
        """``mg_bezier000``: ((best, reasons, first, costs), timing)."""
        base = DATA_BASE
        m = self._put(ctrl, lim)
        best, t = self.arm.call("mg_bezier000", base + self.CTRL, m, int(n), base + self.LIM,
                                int(k1_q16), int(k2_q16), base + self.REASON,
                                base + self.FIRST, base + self.COST)
        return (best, *self._out(m)), t

    def bezier001_coarse(self, ctrl, n: int, lim, geo, n_reg: int, per_sample_cycles: int,
                         setup_cycles: int, cut_cycles: int, k1_q16: int, k2_q16: int):
        """``mg_bezier001_coarse``: ((taken, reasons, first, costs), timing)."""
        base = DATA_BASE
        m = self._put(ctrl, lim, geo)
        taken, t = self.arm.call(
            "mg_bezier001_coarse", base + self.CTRL, m, int(n), base + self.LIM,
            base + self.GEO, int(n_reg), int(per_sample_cycles), int(setup_cycles),
            int(cut_cycles), int(k1_q16), int(k2_q16), base + self.REASON, base + self.FIRST,
            base + self.COST)
        return (taken, *self._out(m)), t

    def bezier001_fine(self, ctrl, n: int, lim, geo, n_reg: int, per_sample_cycles: int,
                       setup_cycles: int, worst_us: int, budget_us: int):
        """``mg_bezier001_fine``: ((index or -1, reasons of those tried), timing); the cache as
        the coarse pass left it."""
        a, base = self.arm, DATA_BASE
        m = self._put(ctrl, lim, geo)
        got, t = a.call("mg_bezier001_fine", base + self.CTRL, m, int(n), base + self.LIM,
                        base + self.GEO, int(n_reg), int(per_sample_cycles), int(setup_cycles),
                        int(worst_us), int(budget_us), base + self.REASON, base + self.TRIED,
                        cold=False)
        tried = struct.unpack("<i", a.read(base + self.TRIED, 4))[0]
        reasons = np.frombuffer(a.read(base + self.REASON, 4 * tried), np.int32)
        return (got, reasons), t

    # -- 001's passes in slices of the control steps (mg_bezier001_coarse_slice, _fine_slice)
    def start_pass(self, ctrl, lim, geo) -> int:
        """Put a pass's candidates and tests in memory, its slice state at the start; returns
        the number of candidates."""
        m = self._put(ctrl, lim, geo)
        self.arm.write(self.STATE, bytes(8))
        return m

    def pass_state(self) -> tuple[int, int]:
        """(next candidate, modelled cycles of the pass so far) after the last slice."""
        return struct.unpack("<ii", self.arm.read(DATA_BASE + self.STATE, 8))

    def bezier001_coarse_slice(self, m: int, n: int, n_reg: int, per_sample_cycles: int,
                               setup_cycles: int, cut_cycles: int, k1_q16: int, k2_q16: int,
                               slice_end_cycles: int, cold: bool = True):
        """One slice of the coarse pass put by :meth:`start_pass`: (curves taken, -1 while it
        goes on; timing). Its outputs so far: :meth:`coarse_outputs`."""
        base = DATA_BASE
        return self.arm.call(
            "mg_bezier001_coarse_slice", base + self.CTRL, m, int(n), base + self.LIM,
            base + self.GEO, int(n_reg), int(per_sample_cycles), int(setup_cycles),
            int(cut_cycles), int(k1_q16), int(k2_q16), int(slice_end_cycles), base + self.STATE,
            base + self.REASON, base + self.FIRST, base + self.COST, cold=cold)

    def coarse_outputs(self, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(reasons, first violated samples, costs) of the coarse pass's ``m`` candidates."""
        return self._out(m)

    def bezier001_fine_slice(self, m: int, n: int, n_reg: int, per_sample_cycles: int,
                             setup_cycles: int, worst_us: int, budget_us: int,
                             slice_end_cycles: int, cold: bool = True):
        """One slice of the fine check put by :meth:`start_pass`: ((index, -1 for none, -2
        while it goes on; reasons of those tried once it has ended), timing)."""
        a, base = self.arm, DATA_BASE
        got, t = a.call("mg_bezier001_fine_slice", base + self.CTRL, m, int(n),
                        base + self.LIM, base + self.GEO, int(n_reg), int(per_sample_cycles),
                        int(setup_cycles), int(worst_us), int(budget_us),
                        int(slice_end_cycles), base + self.STATE, base + self.REASON,
                        base + self.TRIED, cold=cold)
        if got == -2:
            return (got, None), t
        tried = struct.unpack("<i", a.read(base + self.TRIED, 4))[0]
        return (got, np.frombuffer(a.read(base + self.REASON, 4 * tried), np.int32)), t

