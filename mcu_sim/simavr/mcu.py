"""The simavr MCU backend: the avr-gcc ELF of ``firmware/`` on simavr's ATmega128 core.

Same interface as :class:`mobigrasp.mcu_sim.mcu.Mcu` (mobigrasp.mcu_sim.backend.McuBackend),
but nothing of the firmware is modelled: every instruction of the image that would be flashed
runs on simavr (firmware/simavr/harness.c), 16 cycles per simulated µs. This class is the
board around the chip:

- RX: each host byte is handed to USART0 at its start bit, so its RX-complete interrupt comes
  at its stop bit; a byte that starts while the part's two-byte receive buffer is full is lost
  (data overrun), as on the part.
- Encoders: quadrature levels on PD0..PD3 (INT0..3), edges spread evenly over the interval the
  rig gives (a count reached by now: over the next interval as long as the last one), never
  closer than 10 µs; the harness shows them between the other events (sh_advance_to).
- Sonars: a trigger pulse on PORTC0..4 stops the core; the echo (mcu_sim.avr.sonar's timing)
  is queued in the harness as levels on PE6 (INT6), applied at their cycles (sh_pin_at).
- Servos: simavr 1.6 does not move the OC1x/OC3x pins after an OCRnx write in mode 14, so each
  pulse is computed from the OCRnx/ICRn values latched at the Timer1 period start
  (docs/firmware.md, "simavr").
- Wheels: duty from OCR0/OCR2 while Timer0/Timer2 run, sign from the direction pins.

One harness call runs the core to the rig's next coupling time (and one more per sonar
trigger); it reports the wheel duties and whether Timer1 periods and sent bytes wait, so the
other calls cross into C only when there is something to take.

Counters and flags are read from the firmware's globals in SRAM, at the ELF's symbol addresses.
"""

from __future__ import annotations

from collections.abc import Callable

from mobigrasp.mcu_sim.avr.board import CYCLES_PER_US
from mobigrasp.mcu_sim.avr.sonar import ECHO_DELAY_US, MAX_RANGE_M, echo_width_us
from mobigrasp.mcu_sim.avr.usart import baud_error_pct, baud_rate
from mobigrasp.mcu_sim.firmware.params import Params, param_id
from mobigrasp.mcu_sim.mcu import McuConfig
from mobigrasp.mcu_sim.simavr.build import Elf, SimavrBuildError, build_elf, load_harness
from mobigrasp.mcu_sim.simavr.profile import profile_stats

_mod = load_harness()
ffi, lib = _mod.ffi, _mod.lib

_PORT = {c: i for i, c in enumerate("ABCDEFG")}
_ECHO_PORT, _ECHO_BIT = _PORT["E"], 6
_SERVO_PRESCALE = 8
_COUNTERS = ("bad_frames", "not_ready", "unexpected", "tx_dropped", "limit_hits",
             "watchdog_trips", "telemetry_sent")
_PARSER = ("frames_ok", "crc_errors", "oversize", "unknown_type", "bad_version", "truncated",
           "cobs_errors", "garbage_bytes", "bytes_in", "recovered")
# frame_parser_t: buf[70], len, skipping, start, then the stats; dup_filter_t: tag[64],
# crc[64] (16 bit), result[64], newest (16 bit), then duplicates (AVR structs are unpadded)
_PARSER_STATS_OFF = 73
_DUP_DUPLICATES_OFF = 258
_RX_HEAD_OFF, _RX_TAIL_OFF, _RX_OVERRUNS_OFF = 128, 129, 130
_PARAM_TELEMETRY_HZ_ROW = 1  # params_values[I_TELEMETRY_HZ] (fw/params.h), int32 rows
_FLAGS = ("drive_enabled", "handshake", "stopped", "limit_flag", "reset_flag",
          "watchdog_tripped")


class SimavrMcu:
    """One simavr ATmega128 running the firmware ELF."""

    def __init__(self, config: McuConfig | None = None,
                 defines: dict[str, int | str] | None = None,
                 elf: Elf | None = None) -> None:
        self.config = cfg = config or McuConfig()
        defines = dict(defines or {})
        if cfg.params:
            # build-time PARAM choices go into the image (hal_boot_param), checked as a
            # PARAM_SET is: no build can widen a safety limit either
            check = Params()
            chosen = {}
            for key, value in cfg.params.items():
                pid = param_id(key)
                if check.check(pid, int(value)):
                    raise ValueError(f"parameter {key}={value} refused")
                chosen[pid] = int(value)
            defines["FW_BOOT_PARAMS"] = ",".join(f"{{{pid},{v}}}" for pid, v in
                                                 sorted(chosen.items()))
        self.elf = elf or build_elf(defines)
        rx = self.elf.addr("fw_rx")
        h = lib.sh_new(str(self.elf.path).encode(), rx + _RX_HEAD_OFF, rx + _RX_OVERRUNS_OFF,
                       self.elf.addr("__bss_end"))
        if h == ffi.NULL:
            raise SimavrBuildError(f"{self.elf.path}: simavr could not load it")
        self._h = ffi.gc(h, lib.sh_free)
        lib.sh_set_loop_addr(self._h, self.elf.symbols.get("fw_loop", 0))
        lib.sh_set_idle_addrs(self._h, rx + _RX_TAIL_OFF, self.elf.addr("tx_head"),
                              self.elf.addr("tx_tail"), self.elf.addr("next_telemetry_us"),
                              self.elf.addr("params_values") + 4 * _PARAM_TELEMETRY_HZ_ROW)
        bit = 8 if cfg.u2x else 16
        self.byte_cycles = 10 * bit * (cfg.ubrr + 1)
        lib.sh_set_byte_cycles(self._h, self.byte_cycles)
        self._cycle = 0
        if not lib.sh_line_init(self._h, cfg.line_capacity_bytes):
            raise MemoryError(f"no room for a {cfg.line_capacity_bytes}-byte RX line")
        self._rx_line_free = 0
        self._rx_line_dropped = 0
        self._tx_bytes = 0
        self._out = ffi.new("sh_outputs_t *")  # filled by each sh_advance_to
        self._tx_due = 0  # sent bytes waiting at the last advance (none can come without one)
        self._enc_last_call = 0
        self._enc_bad = 0
        self._provider: Callable[[int], float | None] | None = None
        self._widths_ns = [0] * 6
        self._falls: list[tuple[int, int, int]] = []  # (cycle, channel, width ns) to come
        self._pulses_us: tuple[float, ...] = (0.0,) * 6
        self._trig_idx = ffi.new("uint8_t[64]")
        self._trig_cyc = ffi.new("uint64_t[64]")
        self._per_cyc = ffi.new("uint64_t[64]")
        self._per_regs = ffi.new("uint16_t[]", 64 * 9)
        self._tx_buf = ffi.new("uint8_t[4096]")
        self._tx_cyc = ffi.new("uint64_t[4096]")
        self._rd = ffi.new("uint8_t[64]")
        self._duty = ffi.new("int16_t[2]")
        self._idle_cycle = ffi.new("uint64_t *")

    # -- time ----------------------------------------------------------------------------------
    @property
    def now_us(self) -> int:
        """Current simulated time in µs."""
        return self._cycle // CYCLES_PER_US

    def advance_to(self, t_us: int) -> None:
        """Run the core until simulated time ``t_us``."""
        target = int(t_us) * CYCLES_PER_US
        if target < self._cycle:
            raise ValueError(f"cannot go back in time from {self.now_us} to {t_us} us")
        h, out = self._h, self._out
        while True:
            # the RX line's bytes, the echo levels and the encoder edges before the target are
            # handled by the harness itself (sh_advance_to), each at its cycle
            rc = lib.sh_advance_to(h, target, out)
            if rc == 0:
                break
            if rc != 1:
                raise RuntimeError(f"simavr: the firmware stopped (core state "
                                   f"{lib.sh_state(h)}) at cycle {lib.sh_cycle(h)}")
            self._triggers()  # a sonar trigger: schedule its echo, then run on
        self._cycle = target
        self._tx_due = out.tx_due
        if out.periods or self._falls:
            self._periods()

    @property
    def events(self) -> int:
        """Runs of the core between two event times so far."""
        return lib.sh_events(self._h)

    def advance_outputs(self, t_us: int) -> tuple[tuple[float, ...], tuple[int, int]]:
        """:meth:`advance_to`, then (:meth:`servo_pulses_us`, :meth:`wheel_duty`)."""
        self.advance_to(t_us)
        duty = self._out.duty
        return self._pulses_us, (duty[0], duty[1])

    def _pin_at(self, cycle: int, port: int, bit: int, level: int) -> None:
        if not lib.sh_pin_at(self._h, cycle, port, bit, level):
            raise RuntimeError(f"simavr: more than the harness's queue of pin levels to come "
                               f"at cycle {cycle}")

    def _triggers(self) -> None:
        n = lib.sh_triggers_take(self._h, self._trig_idx, self._trig_cyc, 64)
        for i in range(n):
            index, cycle = self._trig_idx[i], self._trig_cyc[i]
            d = self._range_m(index)
            if d is None:
                continue
            rise = cycle + ECHO_DELAY_US * CYCLES_PER_US
            fall = rise + max(1, round(echo_width_us(d) * CYCLES_PER_US))
            self._pin_at(rise, _ECHO_PORT, _ECHO_BIT, 1)
            self._pin_at(fall, _ECHO_PORT, _ECHO_BIT, 0)

    def _range_m(self, index: int) -> float | None:
        if self._provider is None or index >= self.config.sonar_count:
            return None
        try:
            d = self._provider(index)
        except Exception:  # a provider that fails is a sonar that hears nothing
            return None
        if d is None or isinstance(d, bool) or not isinstance(d, (int, float)):
            return None
        if not d == d or d < 0.0:  # NaN or negative
            return None
        return float(d) if d <= MAX_RANGE_M else None

    def _periods(self) -> None:
        n = lib.sh_periods_take(self._h, self._per_cyc, self._per_regs, 64)
        regs = self._per_regs
        for i in range(n):
            start = self._per_cyc[i]
            r = [regs[9 * i + k] for k in range(9)]
            tccra = (r[8] & 0xFF, r[8] >> 8)
            for ch in range(6):
                timer = ch // 3
                com = (tccra[timer] >> (6 - 2 * (ch % 3))) & 0b11
                icr = r[6 + timer]
                if com != 0b10 or r[ch] >= icr:  # not non-inverting, or stays high
                    continue
                cycles = (r[ch] + 1) * _SERVO_PRESCALE  # from BOTTOM to the compare match
                width_ns = cycles * 1000 // CYCLES_PER_US
                self._falls.append((start + cycles, ch, width_ns))
        if self._falls:
            self._falls.sort()
            changed = False
            while self._falls and self._falls[0][0] <= self._cycle:
                _, ch, width = self._falls.pop(0)
                if self._widths_ns[ch] != width:
                    self._widths_ns[ch] = width
                    changed = True
            if changed:
                self._pulses_us = tuple(w / 1000.0 for w in self._widths_ns)

    def run_until_booted(self, limit_us: int = 100_000, step_us: int = 100) -> int:
        """Advance in ``step_us`` steps until the firmware's main loop has begun (its start-up,
        about 2.2 ms after reset, is over: docs/firmware.md) and return that time in µs; bytes
        sent from about 0.44 ms after the reset on are received. Raises if it has not by
        ``limit_us`` from now."""
        end = self.now_us + int(limit_us)
        while not lib.sh_booted(self._h):
            if self.now_us >= end:
                raise SimavrBuildError(f"{self.elf.path}: no main loop within {limit_us} us")
            self.advance_to(min(end, self.now_us + int(step_us)))
        return self.now_us

    def reset(self) -> None:
        """A power-on reset now: ``.data``/``.bss`` zeroed and the RAM above painted again as on
        a new core, the harness's simavr settings applied again (firmware/simavr/harness.c,
        sh_reset), the firmware starts from its reset vector."""
        lib.sh_reset(self._h)
        lib.sh_enc_show_all(self._h)  # the wheels did not move: their pins keep their levels
        self._falls.clear()

    # -- UART ----------------------------------------------------------------------------------
    def uart_rx(self, data: bytes, start_us: int | None = None) -> int:
        """Put ``data`` on the RX line from ``start_us`` (default and minimum: now)."""
        start = self._cycle if start_us is None else max(int(start_us) * CYCLES_PER_US,
                                                          self._cycle)
        start = max(start, self._rx_line_free)
        data = bytes(data)
        take = lib.sh_line_put(self._h, start, data, len(data))
        self._rx_line_dropped += len(data) - take
        if take:
            self._rx_line_free = start + take * self.byte_cycles
        return take

    def uart_tx_take(self) -> list[tuple[int, bytes]]:
        """Bytes the firmware sent since the last call: ``(t_us their stop bit left, bytes)``,
        one chunk per run of back-to-back bytes."""
        out: list[tuple[int, bytes]] = []
        if not self._tx_due:
            return out
        self._tx_due = 0
        while True:
            n = lib.sh_tx_take(self._h, self._tx_buf, self._tx_cyc, 4096)
            if n == 0:
                break
            self._tx_bytes += n
            chunk = bytearray()
            last = None
            for i in range(n):
                c = self._tx_cyc[i]
                if last is not None and c - last > self.byte_cycles and chunk:
                    out.append((-(-last // CYCLES_PER_US), bytes(chunk)))
                    chunk = bytearray()
                chunk.append(self._tx_buf[i])
                last = c
            out.append((-(-last // CYCLES_PER_US), bytes(chunk)))
        return out

    def tx_idle_through_us(self) -> int:
        """Simulated µs through which no byte the firmware sends can finish leaving TX0,
        provided nothing more arrives on the RX line: now while bytes are on the line either
        way, queued to send, or received and maybe not yet answered (the core has not slept
        since); else the firmware's next telemetry time, read off the core
        (firmware/simavr/harness.c, sh_tx_idle_through)."""
        now = self._cycle // CYCLES_PER_US
        through = self._idle_cycle
        if not lib.sh_tx_idle_through(self._h, through):
            return 1 << 62  # telemetry off: nothing is sent until something arrives
        return max(now, through[0] // CYCLES_PER_US)

    @property
    def baud(self) -> float:
        """Actual USART0 baud rate."""
        return baud_rate(self.config.ubrr, self.config.u2x)

    @property
    def baud_error_pct(self) -> float:
        """Baud error against 115200 in percent."""
        return baud_error_pct(self.config.ubrr, self.config.u2x)

    # -- outputs -------------------------------------------------------------------------------
    def servo_pulse_us(self, ch: int) -> float:
        """Latest complete pulse width on channel ``ch`` in µs."""
        if not 0 <= ch < 6:
            raise ValueError(f"servo channel must be 0..5, got {ch}")
        return self._pulses_us[ch]

    def servo_pulses_us(self) -> tuple[float, ...]:
        """The six servo pulse widths."""
        return self._pulses_us

    def oc1_pin_widths_us(self) -> tuple[float, float, float]:
        """The last high time the OC1A..C pins themselves showed, in µs (under simavr 1.6 the
        boot widths: what the servos would get without the latched registers)."""
        return tuple(lib.sh_oc1_pin_high_cycles(self._h, ch) / CYCLES_PER_US for ch in range(3))

    def _read(self, addr: int, n: int) -> bytes:
        lib.sh_read(self._h, addr, self._rd, n)
        return bytes(self._rd[0:n])

    def wheel_duty(self) -> tuple[int, int]:
        """Signed duties (left, right), -255..255, from the timers and direction pins."""
        duty = self._duty
        lib.sh_wheel_duty(self._h, duty)
        return duty[0], duty[1]

    # -- inputs --------------------------------------------------------------------------------
    def set_encoder_ticks(self, left: int, right: int, t_us: int | None = None) -> None:
        """Cumulative quadrature counts (left, right) at ``t_us`` (default now), as pin edges
        spread evenly from the count the pins show now; edges of an earlier call still to come
        are replaced. A count reached by now (the rig reads the wheels after each coupling
        step) is spread over the next interval as long as the last: a pin cannot take the
        edges of a whole step at one instant (firmware/simavr/harness.c, sh_enc_set)."""
        now = self._cycle
        t = now if t_us is None else int(t_us) * CYCLES_PER_US
        span = t - now
        if span <= 0:
            span = now - self._enc_last_call
        self._enc_last_call = now
        for side, count in ((0, left), (1, right)):
            if isinstance(count, bool) or not isinstance(count, int):
                self._enc_bad += 1
                continue
            lib.sh_enc_set(self._h, side, now, span, count)

    def set_sonar_provider(self, provider: Callable[[int], float | None] | None) -> None:
        """Set ``provider(index) -> metres | None`` consulted at each trigger pulse."""
        if provider is not None and not callable(provider):
            raise TypeError(f"sonar provider must be callable or None, got {provider!r}")
        self._provider = provider

    # -- diagnostics ---------------------------------------------------------------------------
    def _u32s(self, symbol: str, offset: int, n: int) -> list[int]:
        raw = self._read(self.elf.addr(symbol) + offset, 4 * n)
        return [int.from_bytes(raw[4 * i:4 * i + 4], "little") for i in range(n)]

    def _flags(self) -> dict[str, bool]:
        raw = self._read(self.elf.addr("fw_flags"), len(_FLAGS))
        return {name: bool(raw[i]) for i, name in enumerate(_FLAGS)}

    def safety_flags(self) -> tuple[bool, bool]:
        """(watchdog stop active, host handshake done), read from the firmware's flags."""
        f = self._flags()
        return f["watchdog_tripped"], f["handshake"]

    def limit_hits(self) -> int:
        """Commands the firmware clamped to the joint limits so far."""
        return self._u32s("fw_counters", 4 * _COUNTERS.index("limit_hits"), 1)[0]

    def stats(self) -> dict[str, int]:
        """Counters of the firmware (from SRAM) and of the line."""
        counters = dict(zip(_COUNTERS, self._u32s("fw_counters", 0, len(_COUNTERS)), strict=True))
        raw = self._u32s("fw_parser", _PARSER_STATS_OFF, len(_PARSER))
        parser = dict(zip(_PARSER, raw, strict=True))
        ring_over = self._u32s("fw_rx", _RX_OVERRUNS_OFF, 1)[0]
        line_lost = self._rx_line_dropped + lib.sh_rx_line_lost(self._h)
        out = {
            "rx_bytes": lib.sh_rx_bytes(self._h),
            "tx_bytes": self._tx_bytes,
            "rx_ring_overruns": ring_over,
            "rx_line_dropped": line_lost,
            "overruns": ring_over + line_lost,
            "corrupt_frames": sum(parser[k] for k in ("crc_errors", "cobs_errors", "truncated",
                                                      "oversize", "bad_version")),
            **counters,
            "duplicates": self._u32s("fw_dup", _DUP_DUPLICATES_OFF, 1)[0],
            "events": self.events,
        }
        for key, value in parser.items():
            out[f"parser_{key}"] = value
        out.update(profile_stats(self.profile()))
        return out

    def profile(self) -> dict[str, object]:
        """What the instruction-accurate core measured so far (mcu_sim/simavr/profile.py)."""
        p = ffi.new("sh_profile_t *")
        lib.sh_profile(self._h, p)
        total = lib.sh_cycle(self._h)
        return {
            "isr_max_cycles": {v: p.isr_max_cycles[v] for v in range(35) if p.isr_count[v]},
            "isr_count": {v: p.isr_count[v] for v in range(35) if p.isr_count[v]},
            "irq_off_max_cycles": p.irq_off_max_cycles,
            "irq_off_max_from_pc": p.irq_off_max_from_pc,
            "irq_off_max_to_pc": p.irq_off_max_to_pc,
            "rx_latency_max_cycles": p.rx_latency_max_cycles,
            "sleep_cycles": p.sleep_cycles,
            "total_cycles": total,
            "stack_depth_bytes": p.stack_depth_bytes,
            "loop_max_cycles": p.loop_max_cycles,
            "loop_passes": p.loop_count,
            "rx_line_lost": lib.sh_rx_line_lost(self._h),
        }
