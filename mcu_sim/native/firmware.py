"""The C firmware as the emulator's firmware object: the interface of mcu_sim.firmware.program.

``NativeFirmware(board, overrides)`` has the handlers and the main-loop pass that
:class:`mobigrasp.mcu_sim.mcu.Mcu` calls (``setup``, ``isr_*``, ``loop``,
``next_unprompted_send_us``) and read-only views of the C globals for diagnostics (counters,
flags, servo bank, PARAMs). Before every call the clock the firmware reads (``hal_micros``) is
set from the board; the HAL's output calls come back as the callbacks below, which write the
board's peripheral models exactly as the Python firmware does.

One loaded library has one set of C globals; each instance keeps its own copy and the one
whose copy is loaded is ``_owner``: a call on another instance swaps (two memcpy of the
firmware's state, under a kilobyte), so any number of native MCUs run side by side.
"""

from __future__ import annotations

from mobigrasp.mcu_sim.avr.board import CYCLES_PER_US
from mobigrasp.mcu_sim.firmware.params import PARAM_TABLE
from mobigrasp.mcu_sim.native.build import load

_mod = load()
ffi, lib = _mod.ffi, _mod.lib
_owner: list = [None]  # the NativeFirmware whose state is in the library's globals
_MASK32 = 0xFFFF_FFFF


def _hw():
    return _owner[0].hw


@ffi.def_extern()
def hal_servo_timers_config(tccra, icr):  # noqa: D103 - the HAL call of hal.h
    hw = _hw()
    for timer in (hw.timer1, hw.timer3):
        timer.write_tccra(tccra)
        timer.write_icr(icr)


@ffi.def_extern()
def hal_servo_timers_start(tccrb):  # noqa: D103
    hw = _hw()
    for timer in (hw.timer1, hw.timer3):
        timer.write_tccrb(tccrb, hw.cycle)


@ffi.def_extern()
def hal_servo_ocr(ch, ocr):  # noqa: D103
    hw = _hw()
    if ch < 3:
        hw.timer1.write_ocr(ch, ocr)
    else:
        hw.timer3.write_ocr(ch - 3, ocr)


@ffi.def_extern()
def hal_wheel_start(side):  # noqa: D103
    hw = _hw()
    (hw.wheel_right if side else hw.wheel_left).start(hw.cycle)


@ffi.def_extern()
def hal_wheel_direction(side, reverse):  # noqa: D103
    hw = _hw()
    (hw.wheel_right if side else hw.wheel_left).write_direction(bool(reverse), hw.cycle)


@ffi.def_extern()
def hal_wheel_ocr(side, ocr):  # noqa: D103
    hw = _hw()
    (hw.wheel_right if side else hw.wheel_left).write_ocr(ocr, hw.cycle)


@ffi.def_extern()
def hal_uart_send(data, n):  # noqa: D103
    hw = _hw()
    return 1 if hw.usart0.tx_write(ffi.unpack(data, n), hw.cycle) else 0


@ffi.def_extern()
def hal_uart_rx_lost():  # noqa: D103
    return _hw().usart0.rx_line_dropped & _MASK32


@ffi.def_extern()
def hal_sonar_trigger(index):  # noqa: D103
    hw = _hw()
    hw.sonars.trigger(index, hw.cycle)


@ffi.def_extern()
def hal_boot_param(pid, value):  # noqa: D103
    chosen = _owner[0].overrides.get(pid)
    if chosen is None:
        return 0
    value[0] = chosen
    return 1


class _Ring:
    """The RX ring's indices and overrun count (read-only view)."""

    def __init__(self, fw: NativeFirmware) -> None:
        self._fw = fw

    @property
    def head(self) -> int:
        """Next write index."""
        self._fw.activate()
        return lib.fw_rx.head

    @property
    def tail(self) -> int:
        """Next read index."""
        self._fw.activate()
        return lib.fw_rx.tail

    @property
    def overruns(self) -> int:
        """Bytes dropped because the ring was full."""
        self._fw.activate()
        return lib.fw_rx.overruns

    def __len__(self) -> int:
        self._fw.activate()
        return (lib.fw_rx.head - lib.fw_rx.tail) % 128


class _ParserStats:
    def __init__(self, fw: NativeFirmware) -> None:
        self._fw = fw

    def as_dict(self) -> dict[str, int]:
        """The parser's counters, named as protocol.ParserStats names them."""
        self._fw.activate()
        s = lib.fw_parser.stats
        return {"frames_ok": s.frames_ok, "crc_errors": s.crc_errors, "oversize": s.oversize,
                "unknown_type": s.unknown_type, "bad_version": s.bad_version,
                "truncated": s.truncated, "cobs_errors": s.cobs_errors,
                "garbage_bytes": s.garbage_bytes, "bytes_in": s.bytes_in,
                "recovered": s.recovered}


class _Parser:
    def __init__(self, fw: NativeFirmware) -> None:
        self.stats = _ParserStats(fw)


class _Dup:
    def __init__(self, fw: NativeFirmware) -> None:
        self._fw = fw

    @property
    def duplicates(self) -> int:
        """Copies of executed reliable commands answered again."""
        self._fw.activate()
        return lib.fw_dup.duplicates


class _Servos:
    """The servo bank's arrays, copied out at each read."""

    def __init__(self, fw: NativeFirmware) -> None:
        self._fw = fw

    def _arr(self, name: str) -> list[int]:
        self._fw.activate()
        return list(getattr(lib.fw_servos, name))

    min_us = property(lambda self: self._arr("min_us"), doc="lower pulse limits, µs")
    max_us = property(lambda self: self._arr("max_us"), doc="upper pulse limits, µs")
    latched_q8 = property(lambda self: self._arr("latched_q8"), doc="widths in force, Q8 µs")
    pending_q8 = property(lambda self: self._arr("pending_q8"), doc="widths written, Q8 µs")
    target_q8 = property(lambda self: self._arr("target_q8"), doc="targets, Q8 µs")


class _Params:
    def __init__(self, fw: NativeFirmware) -> None:
        self._fw = fw

    def get(self, pid: int) -> int | None:
        """Value of ``pid``, None if unknown."""
        self._fw.activate()
        out = ffi.new("int32_t *")
        return out[0] if lib.params_get(pid, out) else None

    @property
    def values(self) -> list[int]:
        """Current values in table order (a copy)."""
        self._fw.activate()
        return list(lib.params_values)


class _Wheel:
    def __init__(self, fw: NativeFirmware, side: int) -> None:
        self._fw, self._side = fw, side

    @property
    def target_mmps(self) -> int:
        """The speed target in force, mm/s."""
        self._fw.activate()
        return lib.fw_wheels[self._side].target_mmps


class NativeFirmware:
    """The C program on the board's peripheral models; ``hw`` is a mcu_sim.avr.board.Board."""

    def __init__(self, hw, param_overrides: dict[int, int] | None = None) -> None:
        self.hw = hw
        self.overrides: dict[int, int] = {}
        self._state = ffi.new("uint8_t[]", lib.native_state_size())
        self._activate_fresh()
        lib.params_reset()  # the table's values, against which build-time choices are checked
        chosen = dict(param_overrides or {})
        for pid, value in chosen.items():
            # the same checks as a PARAM_SET: no build can widen a safety limit either
            reason = lib.params_check(pid, value) if -2**31 <= value < 2**31 else 1
            if reason:
                raise ValueError(f"parameter {pid}={value} refused (NACK reason {reason})")
        self.overrides = chosen
        self.rx = _Ring(self)
        self.parser = _Parser(self)
        self.dup = _Dup(self)
        self.servos = _Servos(self)
        self.params = _Params(self)
        self.wheels = (_Wheel(self, 0), _Wheel(self, 1))
        self.setup()

    def _activate_fresh(self) -> None:
        owner = _owner[0]
        if owner is not None:
            lib.native_state_save(owner._state)
        lib.native_state_load(self._state)  # all zero: the C globals before main()
        _owner[0] = self

    def activate(self) -> None:
        """Make this instance's copy of the C globals the loaded one."""
        owner = _owner[0]
        if owner is not self:
            if owner is not None:
                lib.native_state_save(owner._state)
            lib.native_state_load(self._state)
            _owner[0] = self

    def _clock(self) -> None:
        if _owner[0] is not self:
            self.activate()
        hw = self.hw
        lib.native_now_us = ((hw.cycle - hw.reset_cycle) // CYCLES_PER_US) & _MASK32

    # -- what the emulator calls -----------------------------------------------------------
    def setup(self) -> None:
        """``main()`` before the loop: the receiving side, then the rest."""
        self._clock()
        lib.fw_setup_rx()
        lib.fw_setup()

    def isr_timer1_ovf(self) -> None:
        """Timer1 (and 3) period start."""
        self._clock()
        lib.fw_isr_timer1_ovf()

    def isr_usart_rx_bytes(self, data: bytes) -> None:
        """Several RX-complete interrupts in a row, oldest first."""
        self._clock()
        lib.native_usart_rx_bytes(data, len(data))

    def isr_usart_rx(self, byte: int) -> None:
        """One RX-complete interrupt."""
        self.isr_usart_rx_bytes(bytes((byte,)))

    def isr_encoder(self, side: int, edges: int) -> None:
        """``edges`` encoder interrupts of one sign on wheel ``side``."""
        self._clock()
        lib.native_encoder_edges(side, edges)

    def isr_echo(self, index: int, level: int) -> None:
        """Echo pin of sonar ``index`` changed to ``level``."""
        self._clock()
        lib.fw_isr_echo(index, level)

    def loop(self) -> int:
        """One main-loop pass; the next due time in µs since reset (unwrapped)."""
        self._clock()
        now = lib.native_now_us
        due = lib.fw_loop()
        full_now = (self.hw.cycle - self.hw.reset_cycle) // CYCLES_PER_US
        return full_now + (((due - now + 0x8000_0000) & _MASK32) - 0x8000_0000)

    def load_stats(self, elapsed_cycles: int) -> dict[str, int]:
        """Nothing: the C program runs on the host here, its cycles are not the AVR's
        (``--mcu simavr`` measures them, the Python model charges them)."""
        return {}

    def work_pending(self) -> bool:
        """True while a handler left work for the main loop (``fw_work_pending``)."""
        self.activate()
        return bool(lib.fw_work_pending())

    def next_unprompted_send_us(self) -> int | None:
        """The next telemetry time (µs since reset), None when telemetry is off."""
        self.activate()
        off = ffi.new("uint8_t *")
        due = lib.fw_next_unprompted_send_us(off)
        if off[0]:
            return None
        hw = self.hw
        full_now = (hw.cycle - hw.reset_cycle) // CYCLES_PER_US
        return full_now + (((due - full_now + 0x8000_0000) & _MASK32) - 0x8000_0000)

    # -- diagnostics -----------------------------------------------------------------------
    def corrupt_frames(self) -> int:
        """Frames the parser rejected as damaged."""
        self.activate()
        return lib.fw_corrupt_frames()

    def overruns(self) -> int:
        """Bytes lost on reception: RX ring full, or more than the line could carry."""
        self.activate()
        return lib.fw_rx.overruns + self.hw.usart0.rx_line_dropped

    def _counter(name: str, doc: str):  # noqa: N805 - a property factory in the class body
        def get(self) -> int:
            self.activate()
            return getattr(lib.fw_counters, name)
        return property(get, doc=doc)

    def _flag(name: str, doc: str):  # noqa: N805
        def get(self) -> bool:
            self.activate()
            return bool(getattr(lib.fw_flags, name))
        return property(get, doc=doc)

    bad_frames = _counter("bad_frames", "frames NACKed because their payload did not decode")
    not_ready = _counter("not_ready", "commands before the handshake")
    unexpected = _counter("unexpected", "messages that are not for the MCU")
    tx_dropped = _counter("tx_dropped", "frames that did not fit the TX ring")
    limit_hits = _counter("limit_hits", "commands clamped to a limit")
    watchdog_trips = _counter("watchdog_trips", "watchdog stops")
    telemetry_sent = _counter("telemetry_sent", "telemetry frames queued")
    handshake = _flag("handshake", "HELLO accepted")
    watchdog_tripped = _flag("watchdog_tripped", "watchdog stop in force")
    stopped = _flag("stopped", "STOP in force")
    drive_enabled = _flag("drive_enabled", "wheel PI running")
    del _counter, _flag

    @property
    def last_valid_us(self) -> int:
        """Time of the last valid frame (µs since reset, 32 bits)."""
        self.activate()
        return lib.fw_last_valid_us

    @property
    def enc_count(self) -> list[int]:
        """Encoder counts (left, right) as the firmware has them."""
        self.activate()
        return [lib.fw_enc_count[0], lib.fw_enc_count[1]]


def c_param_table() -> tuple[tuple[int, int, int, int, bool, bool], ...]:
    """The C firmware's PARAM table: (id, default, min, max, writable, safety) per row."""
    pid, d, lo, hi, w, safe = (ffi.new(t) for t in ("uint16_t *", "int32_t *", "int32_t *",
                                                    "int32_t *", "uint8_t *", "uint8_t *"))
    rows = []
    for i in range(len(PARAM_TABLE)):
        lib.params_row(i, pid, d, lo, hi, w, safe)
        rows.append((pid[0], d[0], lo[0], hi[0], bool(w[0]), bool(safe[0])))
    return tuple(rows)
