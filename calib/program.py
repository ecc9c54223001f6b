"""Whole control steps and whole frame pipelines of the host program as ARM920T code.

A shipped scenario runs in process with the Python host program and a :class:`Recorder` on its
interface (HostApp's ``recorder`` hook): every serial chunk and frame it was given, every
``advance_to``, and what it wrote (serial bytes) and traced (events). :class:`Replay` gives the
same calls, in the same order, to the C program (hostc/, ``calib_program.h``) built as the
static ARMv4T ELF of ``make hostc-arm`` and run under unicorn, and checks after each quantum
that its serial bytes and trace events are the Python program's: the code timed is the code
that ran the scenario. Each ``advance_to`` is cut at every control tick and frame arrival, so
one call runs one tick or one frame.

The samples are timed with calib/timing.py's model and D-cache, from a cold cache (the frame
is a new DMA buffer; a control step follows vision, which has had the cache):

- a **control step**: the telemetry parsed since the tick before (``mg_app_on_uart``) and the
  tick itself (the link's service, the task's inputs and step, the commands encoded, the
  heartbeat), against what the model charged it: the ``control`` and ``protocol`` stages
  (``control_base_cycles``, ``handover_cycles`` in a step handed a vision job's results, the
  task's counts and ``protocol_cycles_per_byte``, host/app.py);
- a **frame pipeline**: the detectors the frame's job ran (their ``detect`` entries of the
  program's table, each call from entry to return), against their charge (the job's ARM9 time
  less the modelled frame overhead, which stands for the CAMIF's hand-over: no code of the
  program).

The rest of the run goes on untimed on a second unicorn core over the same memory (the hooks
that time a block cost ~400x its run time).
"""

from __future__ import annotations

import ctypes
import json
import mmap
import struct
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mobigrasp.calib import arm, timing
from mobigrasp.calib.arm import I64, Timing
from mobigrasp.host.app import HostConfig
from mobigrasp.host.budget import FCLK_HZ

PAGE = 0x1000
# above the image (its .bss holds the detectors' scratch and the stage histograms: 17 MB) with
# room to grow; _map refuses an image that reaches it
HEAP_BASE = 0x0400_0000
HEAP_SIZE = 0x0200_0000
STACK_TOP = 0x0610_0000
STACK_SIZE = 0x0004_0000
# the heap: the program's state, then the I/O buffers and the frames it holds
PROGRAM, IO, FRAMES = 0x0, 0x40_0000, 0x48_0000
IO_BYTES = 0x8_0000
FRAME_SLOTS = 16  # more than the program's MG_APP_FRAMES queue: a slot is free when reused
FRAME_SLOT_BYTES = 640 * 480 * 3
# the scenarios of each paper method whose steps are replayed (shipped scenarios)
SCENARIOS = {"000": ("paper000-exp1", "paper000-exp2"),
             "001": ("paper001-sim1", "paper001-sim2"),
             "002": ("paper002-marker", "paper002-cylinder-moving")}


# the C program's calibration entries (hostc/calib_program.h), kept in the ELF built for it
ENTRIES = ("mg_calib_program_open", "mg_calib_table", "mg_calib_stage_us",
           "mg_calib_take_output")


def build(progress=None) -> Elf:
    """The host program's ELF (``make hostc-arm``) with :data:`ENTRIES`, read."""
    from mobigrasp.calib.armhost import build_elf

    if progress:
        progress("building the ARM host program (make hostc-arm)")
    return Elf.read(build_elf(ENTRIES))


class ReplayMismatch(AssertionError):
    """The C program's output differs from the Python program's at a recorded quantum."""


def _up(n: int) -> int:
    return (n + PAGE - 1) & ~(PAGE - 1)


@dataclass(frozen=True)
class Elf:
    """A static ARM ELF's loadable segments ((vaddr, file bytes, memory size, writable)), its
    functions and objects by name."""

    segments: tuple[tuple[int, bytes, int, bool], ...]
    symbols: dict[str, int]

    @classmethod
    def read(cls, path: Path) -> Elf:
        data = Path(path).read_bytes()
        if data[:4] != b"\x7fELF" or data[4] != 1 or data[5] != 1:
            raise arm.ToolchainError(f"{path}: not a 32-bit little-endian ELF")
        phoff, = struct.unpack_from("<I", data, 28)
        phentsize, phnum = struct.unpack_from("<HH", data, 42)
        segs = []
        for k in range(phnum):
            p_type, off, vaddr, _pa, filesz, memsz, flags, _al = struct.unpack_from(
                "<8I", data, phoff + k * phentsize)
            if p_type == 1:  # PT_LOAD
                segs.append((vaddr, data[off:off + filesz], memsz, bool(flags & 2)))
        nm = subprocess.run([arm.CC[:-3] + "nm", str(path)], capture_output=True, text=True,
                            check=True).stdout
        syms = {}
        for line in nm.splitlines():
            parts = line.split()
            if len(parts) == 3 and parts[1] in "tTbBdD":
                syms.setdefault(parts[2], int(parts[0], 16))
        return cls(tuple(segs), syms)


class ProgramArm9(arm.Arm9):
    """The host program's ELF on two unicorn cores over one memory: :meth:`call` with
    ``timed`` runs on the core with the timing model's hooks, without on a bare one. While a
    timed call is inside one of ``vision_entries`` (a detector's ``detect``, entry to
    return) its cycles go to :attr:`vision` instead of the call's timing."""

    def __init__(self, elf: Elf, line_fill_cycles: int = timing.LINE_FILL_CYCLES) -> None:
        self.elf = elf
        self._buffers: list = []
        self._regions: list[tuple[int, int, int]] = []  # (address, size, host pointer)
        super().__init__(arm.Image(b"", elf.symbols), line_fill_cycles)
        self.stack_top = STACK_TOP
        self.fast = arm.new_uc()
        for addr, size, ptr in self._regions:
            self.fast.mem_map_ptr(addr, size, 7, ptr)
        self.vision_entries: frozenset[int] = frozenset()
        self.vision = Timing()
        self._outer: Timing | None = None
        self._vision_ret: int | None = None

    def _shared(self, uc, addr: int, size: int) -> None:
        buf = mmap.mmap(-1, size)
        ptr = ctypes.addressof(ctypes.c_char.from_buffer(buf))
        self._buffers.append(buf)
        self._regions.append((addr, size, ptr))
        uc.mem_map_ptr(addr, size, 7, ptr)

    def _map(self, uc) -> tuple[int, int]:
        lo = min(a for a, _, _, _ in self.elf.segments) & ~(PAGE - 1)
        hi = _up(max(a + m for a, _, m, _ in self.elf.segments))
        if hi > HEAP_BASE:
            raise ValueError(f"the program's image ends at {hi:#x}, past the calibration's "
                             f"heap at {HEAP_BASE:#x} (calib/program.py HEAP_BASE)")
        self._shared(uc, arm.STOP, PAGE)
        self._shared(uc, lo, hi - lo)
        for addr, data, _, _ in self.elf.segments:
            uc.mem_write(addr, data)
        self._shared(uc, HEAP_BASE, HEAP_SIZE)
        self._shared(uc, STACK_TOP - STACK_SIZE, STACK_SIZE)
        # the D-cache sees the data: the writable segment on (not the text and its constants,
        # as for the kernels' image)
        rw = min(a for a, _, _, w in self.elf.segments if w)
        return rw, STACK_TOP - 1

    def _on_block(self, uc, address, size, user):
        if self._vision_ret is None:
            if address in self.vision_entries:
                from unicorn.arm_const import UC_ARM_REG_LR

                self._vision_ret = uc.reg_read(UC_ARM_REG_LR)
                self._outer, self._t = self._t, self.vision
        elif address == self._vision_ret:
            self._vision_ret = None
            self._t = self._outer
        super()._on_block(uc, address, size, user)

    def call(self, symbol: str, *args, cold: bool = True, timed: bool = True):
        """``symbol(args)``: (r0, timing) as :meth:`Arm9.call`, on the bare core (timing
        empty) unless ``timed``."""
        if timed:
            self.vision = Timing()
            self._vision_ret = None
            return super().call(symbol, *args, cold=cold)
        from unicorn.arm_const import UC_ARM_REG_R0

        arm.run(self.fast, self.elf.symbols[symbol], args, self.stack_top)
        r0 = self.fast.reg_read(UC_ARM_REG_R0)
        return r0 - (1 << 32) if r0 & 0x8000_0000 else r0, Timing()

    def call64(self, symbol: str, *args) -> int:
        """An int64_t function's value (r0, r1), untimed."""
        from unicorn.arm_const import UC_ARM_REG_R0, UC_ARM_REG_R1

        arm.run(self.fast, self.elf.symbols[symbol], args, self.stack_top)
        v = self.fast.reg_read(UC_ARM_REG_R0) | self.fast.reg_read(UC_ARM_REG_R1) << 32
        return v - (1 << 64) if v >> 63 else v

    def write(self, address: int, data) -> int:
        """Copy bytes to ``address``; returns it."""
        self.uc.mem_write(address, bytes(data))
        return address


@dataclass
class Recorder:
    """HostApp's ``recorder``: the program's interface calls in order (kind, args)."""

    calls: list[tuple] = field(default_factory=list)

    def __call__(self, kind: str, *args) -> None:
        if kind == "frame" and args[3] is not None:
            args = (*args[:3], np.array(args[3], copy=True))
        elif kind == "events":
            args = (json.loads(json.dumps(args[0])),)
        elif kind == "output":
            args = (b"".join(w for _, w in args[0]),)
        self.calls.append((kind, *args))


@dataclass(frozen=True)
class Recording:
    """A scenario's run of the Python host program: its configuration (what ``--config`` gives
    a host program: the method, its parameters, the camera, the task's settings) and calls."""

    scenario: str
    config: dict
    calls: list[tuple]
    trace_sha256: str | None

    @property
    def method(self) -> str:
        return str(self.config.get("method", "000"))


@dataclass
class Sample:
    """One timed step: its kind ("control" or "frame"), time, modelled µs, timing."""

    kind: str
    t_us: int
    modelled_us: int
    timing: Timing


def _events(text: bytes) -> list:
    return json.loads(b"[" + text + b"]") if text else []


class Replay:
    """A :class:`Recording` replayed on the C program under unicorn (:class:`ProgramArm9`),
    timing the control ticks in ``ticks_us`` and the frames (by arrival) in ``frames_us``."""

    def __init__(self, machine: ProgramArm9, rec: Recording) -> None:
        self.m = machine
        self.rec = rec
        self.p = HEAP_BASE + PROGRAM
        self.io = HEAP_BASE + IO
        text = json.dumps(rec.config).encode()  # as the in-process C program is given it
        n_det, _ = machine.call("mg_calib_program_open", self.p, self.m.write(self.io, text),
                                len(text), timed=False)
        if n_det < 0:
            raise ValueError(f"the C program refuses {rec.scenario}'s configuration (or has "
                             f"no method {rec.method})")
        table, _ = machine.call("mg_calib_table", self.p, timed=False)
        words = struct.unpack(f"<{6 * n_det}I", machine.read(table & 0xFFFF_FFFF, 24 * n_det))
        # mg_detector_t on ARM: name, ctx, snapshot, detect, front_end, front_end_us
        machine.vision_entries = frozenset(words[6 * i + 3] for i in range(n_det))
        self.names = {k: self.m.write(self.io + 0x100 + 16 * i, k.encode() + b"\0")
                      for i, k in enumerate(("control", "protocol", "frame"))}
        # the C program's configuration is the default one (program.c)
        cfg = HostConfig()
        self.period_us = cfg.control_period_us
        self.frame_overhead_us = cfg.frame_overhead_cycles * 1_000_000 // FCLK_HZ
        self._slot = 0
        self._pending: list[int] = []  # arrival times of the frames given and not run
        self._next_tick = 0
        self._uart_t = Timing()  # the bytes parsed since the last tick, when the next is timed
        self._until = 0
        self.quanta = 0

    def _stage_us(self, name: str | None) -> int:
        return self.m.call64("mg_calib_stage_us", self.p, self.names[name] if name else 0)

    def _budget(self) -> tuple[int, int]:
        """(control + protocol, vision) modelled µs so far."""
        ctrl = self._stage_us("control") + self._stage_us("protocol")
        return ctrl, self._stage_us(None) - ctrl

    def run(self, ticks_us: set[int], frames_us: set[int]) -> list[Sample]:
        """Replay every call; the samples timed. ReplayMismatch at the first quantum whose
        serial bytes or events differ from the Python program's."""
        m, out = self.m, []
        for call in self.rec.calls:
            kind = call[0]
            if kind == "uart":
                data, arrival = call[1], call[2]
                timed = self._next_tick in ticks_us
                addr = m.write(self.io + 0x1000, data)
                _, t = m.call("mg_app_on_uart", self.p, addr, len(data), I64(arrival),
                              timed=timed)
                if timed:
                    self._uart_t = Timing.sum(self._uart_t, t)
            elif kind == "frame":
                seq, capture, arrival, rgb = call[1:]
                addr, h, w = 0, 0, 0
                if rgb is not None:
                    h, w = rgb.shape[:2]
                    addr = HEAP_BASE + FRAMES + FRAME_SLOT_BYTES * self._slot
                    self._slot = (self._slot + 1) % FRAME_SLOTS
                    m.write(addr, np.ascontiguousarray(rgb, np.uint8).tobytes())
                m.call("mg_app_on_frame", self.p, I64(seq), I64(capture), I64(arrival), addr,
                       w, h, timed=False)
                self._pending.append(arrival)
            elif kind == "advance":
                out += self._advance(call[1], ticks_us, frames_us)
                self.quanta += 1
            elif kind == "output":
                got = self._take_output(self._until)
                if got != call[1]:
                    raise ReplayMismatch(f"{self.rec.scenario}: serial bytes differ before "
                                         f"{self._until} us: {got.hex()} != {call[1].hex()}")
            elif kind == "events":
                got = self._take_events()
                if got != call[1]:
                    raise ReplayMismatch(f"{self.rec.scenario}: events differ before "
                                         f"{self._until} us: {got} != {call[1]}")
        return out

    def _advance(self, until: int, ticks_us: set[int], frames_us: set[int]) -> list[Sample]:
        """``advance_to(until)`` cut at each tick and frame arrival (one call each)."""
        self._until = until
        times = sorted({a for a in self._pending if a < until}
                       | set(range(self._next_tick, until, self.period_us)))
        samples = []
        for b in [*times, None]:
            stop = until if b is None else b + 1
            timed = b is not None and (b in ticks_us or b in frames_us)
            before = self._budget() if timed else None
            _, t = self.m.call("mg_app_advance_to", self.p, I64(stop), timed=timed)
            ticked = b is not None and b == self._next_tick
            if b is not None:
                self._pending = [a for a in self._pending if a > b]
            if ticked:
                self._next_tick += self.period_us
            uart_t = self._uart_t
            if ticked:
                self._uart_t = Timing()
            if not timed:
                continue
            ctrl, vision = (x - y for x, y in zip(self._budget(), before, strict=True))
            if ticked and b in ticks_us:
                samples.append(Sample("control", b, ctrl, Timing.sum(uart_t, t)))
            if b in frames_us and self.m.vision.cycles:
                samples.append(Sample("frame", b, vision - self.frame_overhead_us,
                                      self.m.vision))
        return samples

    def _take_output(self, before_us: int) -> bytes:
        n, _ = self.m.call("mg_calib_take_output", self.p, I64(before_us), self.io + 0x1000,
                           IO_BYTES - 0x1000, timed=False)
        if n < 0:
            raise ReplayMismatch(f"{self.rec.scenario}: serial bytes past the replay's buffer")
        return self.m.read(self.io + 0x1000, n)

    def _take_events(self) -> list:
        buf, lenp = self.io + 0x1000, self.io + 0x800
        self.m.call("mg_app_take_events", self.p, buf, IO_BYTES - 0x1000, lenp, timed=False)
        n, = struct.unpack("<I", self.m.read(lenp, 4))
        return _events(self.m.read(buf, n))


def stage_names(method: str) -> tuple[str, str]:
    """The calibration's stages of a method's program: its control steps, its frame pipelines."""
    return f"control_step_{method}", f"frame_pipeline_{method}"


def methods_in_program(elf: Elf | None = None) -> list[str]:
    """The paper methods (:data:`SCENARIOS`) the C program has a row for."""
    machine = ProgramArm9(elf or build())
    out = []
    for method in SCENARIOS:
        text = json.dumps({"method": method}).encode()
        n_det, _ = machine.call("mg_calib_program_open", HEAP_BASE + PROGRAM,
                                machine.write(HEAP_BASE + IO, text), len(text), timed=False)
        if n_det >= 0:
            out.append(method)
    return out


def _spread(values: list[int], n: int | None) -> set[int]:
    if n is None or len(values) <= n:
        return set(values)
    step = len(values) / n
    return {values[int(k * step)] for k in range(n)}


def pick(rec: Recording, per_scenario: int | None) -> tuple[set[int], set[int]]:
    """The ticks and frames (arrival µs) of a recording to time: all, or ``per_scenario`` of
    each spread evenly over the run, the ticks after the first 0.5 s (the HELLO, the
    handshake: no task step yet), the frames the Python program ran detectors on."""
    until = max((c[1] for c in rec.calls if c[0] == "advance"), default=0)
    ticks = list(range(500_000, until, HostConfig().control_period_us))
    arrival = {c[1]: c[3] for c in rec.calls if c[0] == "frame"}
    ran = [arrival[e["seq"]] for c in rec.calls if c[0] == "events"
           for e in c[1] if e.get("ev") == "detect" and e.get("seq") in arrival]
    return _spread(ticks, per_scenario), _spread(sorted(ran), per_scenario)


def scenarios_in_program(elf: Elf) -> list[str]:
    """The shipped scenarios of every method the C program has, in :data:`SCENARIOS` order."""
    return [sc for m in methods_in_program(elf) for sc in SCENARIOS[m]]


def program_steps(elf: Elf, rec: Recording, per_scenario: int | None,
                  line_fill_cycles: int = timing.LINE_FILL_CYCLES):
    """(stage, outputs equal, modelled cycles, timing) of every timed step of ``rec``
    (services/corpus.py ``record_steps``) replayed on the C program; a replay that parts from
    the Python program's gives one unequal row for each stage (modelled and timing empty) and
    stops there."""
    control, frame = stage_names(rec.method)
    ticks, frames = pick(rec, per_scenario)
    try:
        samples = Replay(ProgramArm9(elf, line_fill_cycles), rec).run(ticks, frames)
    except ReplayMismatch:
        for stage in (control, frame):
            yield stage, False, 0, Timing()
        return
    for s in samples:
        yield (control if s.kind == "control" else frame, True,
               s.modelled_us * (FCLK_HZ // 1_000_000), s.timing)
