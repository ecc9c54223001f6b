"""Fault hooks around the rig's parts: the rig itself stays unchanged.

:class:`FaultRig` puts a wrapper around the MCU and the plant the rig talks to:

- :class:`FaultedMcu` (an ``McuBackend``, mobigrasp.mcu_sim.backend): host->MCU bytes through
  :class:`UartFaults` (bit errors, drops, bursts, latency) before the USART sees them; MCU->host
  bytes likewise, held back until their delayed arrival; the MCU reset at ``mcu_reset_at_s``
  (exactly at that time, inside ``advance_to``); a failed motor gets no duty; encoder counts after
  wheel slip; a failed sonar hears no echo. After every ``advance_to`` the :class:`SafetyMonitor`
  judges the MCU's outputs (host silence = stall, crash or a dead line in a burst; recovery is timed
  from the end of a stall or burst and from an MCU reset).
- :class:`FaultedPlant` (the rig's plant): frames dropped on the CAMIF or noisy.
- the host's silence (``host_stall``, ``host_crash_at_s``) is the co-simulation's to apply
  (mobigrasp.cosim.faulted_host.FaultedHost, from the same :class:`RunFaults`). The bytes the MCU
  sent meanwhile are kept off the line by :class:`FaultedMcu`: during a stall they wait in the
  host's UART buffer and arrive at the stall's end; after a crash they are never read (over a
  pty nobody would drain them).

Everything is decided by the plan, the run seed and simulated time.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from mobigrasp.mcu_sim.faults.injectors import RunFaults
from mobigrasp.mcu_sim.faults.plan import FaultPlan
from mobigrasp.mcu_sim.faults.safety import SafetyMonitor


def _byte_us(n: int, baud: int) -> int:
    return -(-n * 10_000_000 // baud)


class FaultedMcu:
    """An ``Mcu`` seen through the faults of the line, the motors, encoders and sonars."""

    def __init__(self, mcu: Any, faults: RunFaults, monitor: SafetyMonitor) -> None:
        self.inner = mcu
        self.faults = faults
        self.monitor = monitor
        self._held: list[tuple[int, bytes]] = []  # MCU->host chunks delayed by latency
        self._recovery_points = faults.recovery_points_us()
        self._any_fault = faults.plan.active()  # asked once per quantum (tx_idle_through_us)
        self.unread_bytes = 0  # MCU bytes a crashed host never read
        if (not faults.to_host.active and faults.crash_us is None and faults.stall is None):
            self.uart_tx_take = self._uart_tx_take_plain
        self.servo_pulses_us = mcu.servo_pulses_us  # never faulted: the MCU's own call
        if not self._any_fault:
            # what tx_idle_through_us answers with nothing planned: the MCU's own call
            self.tx_idle_through_us = mcu.tx_idle_through_us
        self._inner_outputs = mcu.advance_outputs
        if _quiet_at_coupling(faults):
            # Nothing in the plan touches the MCU at its coupling steps (the common case, an
            # empty plan): the rig, which binds these once, calls the MCU directly and the
            # monitor still judges every step. Same results, one Python frame less per call.
            self.advance_to = self._advance_quiet
            self.advance_outputs = self._advance_outputs_quiet
            self.wheel_duty = mcu.wheel_duty
            self.set_encoder_ticks = mcu.set_encoder_ticks

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)

    def tx_idle_through_us(self) -> int | None:
        """The MCU's own answer with an empty plan; None (cannot tell) with any fault planned:
        a reset, a burst or held bytes can put bytes on the line at any time."""
        if self._any_fault:
            return None
        return self.inner.tx_idle_through_us()

    def advance_to(self, t_us: int) -> None:
        """Run the MCU to ``t_us``, resetting it on the way if the plan says so."""
        f, mcu = self.faults, self.inner
        if f.mcu_reset_due(mcu.now_us, t_us):
            mcu.advance_to(f.mcu_reset_us)
            mcu.reset()
            self.monitor.fault(f.mcu_reset_us)
        mcu.advance_to(t_us)
        while self._recovery_points and self._recovery_points[0] <= t_us:
            self.monitor.fault(self._recovery_points.pop(0))
        tripped, handshake = mcu.safety_flags()
        self.monitor.observe(t_us, mcu.wheel_duty(), mcu.servo_pulses_us(), tripped, handshake,
                             f.host_silent(t_us) or f.line_dead(t_us))

    def _advance_quiet(self, t_us: int) -> None:
        """:meth:`advance_to` when the plan has no reset, stall, crash or burst."""
        mcu = self.inner
        mcu.advance_to(t_us)
        tripped, handshake = mcu.safety_flags()
        self.monitor.observe(t_us, mcu.wheel_duty(), mcu.servo_pulses_us(), tripped, handshake,
                             False)

    def _advance_outputs_quiet(self, t_us: int) -> tuple[tuple[float, ...], tuple[int, int]]:
        """:meth:`advance_outputs` when the plan leaves the coupling step alone: the outputs the
        monitor judges are the ones handed to the rig (read once)."""
        mcu = self.inner
        pulses, duty = self._inner_outputs(t_us)
        tripped, handshake = mcu.safety_flags()
        self.monitor.observe(t_us, duty, pulses, tripped, handshake, False)
        return pulses, duty

    def advance_outputs(self, t_us: int) -> tuple[tuple[float, ...], tuple[int, int]]:
        """:meth:`advance_to`, then (servo pulses, the duties that reach the motors)."""
        self.advance_to(t_us)
        return self.servo_pulses_us(), self.wheel_duty()

    def servo_pulses_us(self) -> tuple[float, ...]:
        """The MCU's six pulse widths in one call (the servo outputs are not faulted)."""
        return self.inner.servo_pulses_us()

    def uart_rx(self, data: bytes, start_us: int | None = None) -> int:
        """Host bytes onto the RX line, corrupted and delayed by the plan."""
        u = self.faults.to_mcu
        start = self.inner.now_us if start_us is None else start_us
        out, _, _ = u.apply(bytes(data), start)
        return self.inner.uart_rx(out, u.deliver_us(start)) if out else 0

    def uart_tx_take(self) -> list[tuple[int, bytes]]:
        """MCU bytes that reached the host's UART by now (corrupted, delayed).

        A host that is not running reads nothing: bytes arriving during a stall wait in its
        UART buffer and are handed over at the stall's end; bytes arriving after a crash are
        never read (dropped here, so nothing piles up in a pty that no one reads)."""
        taken = self.inner.uart_tx_take()
        if not taken and not self._held:  # most coupling steps: nothing sent, nothing held
            return []
        return self._deliver(taken)

    def _uart_tx_take_plain(self) -> list[tuple[int, bytes]]:
        """:meth:`uart_tx_take` when the plan leaves the MCU->host bytes alone (no bit errors,
        drops, latency or burst on that stream, no host stall or crash): every chunk arrives
        whole when its last bit left, so it is handed on as it is (and counted)."""
        taken = self.inner.uart_tx_take()
        if not taken:
            return taken
        if self._held or taken[-1][0] > self.inner.now_us:
            return self._deliver(taken)  # not seen in practice; the general path decides
        n = 0
        for _, d in taken:
            if not d:
                return self._deliver(taken)  # an empty chunk is dropped there
            n += len(d)
        u = self.faults.to_host
        u.byte_index += n  # what UartFaults.apply counts for bytes it passes unchanged
        u.bytes_in += n
        return taken

    def _deliver(self, taken: list[tuple[int, bytes]]) -> list[tuple[int, bytes]]:
        u, f = self.faults.to_host, self.faults
        for t_us, data in taken:
            out, _, _ = u.apply(data, t_us - _byte_us(len(data), u.baud))
            arrival = u.deliver_us(t_us)
            if f.host_crashed(arrival):
                self.unread_bytes += len(out)
                continue
            if f.host_stalled(arrival):
                arrival = f.host_stall_end_us()
            if out:
                self._held.append((arrival, out))
        now = self.inner.now_us
        ready = [c for c in self._held if c[0] <= now]
        self._held = [c for c in self._held if c[0] > now]
        return ready

    def wheel_duty(self) -> tuple[int, int]:
        """Duties that reach the motors (a failed motor gets none)."""
        left, right = self.inner.wheel_duty()
        return self.faults.wheel_duty(left, right, self.inner.now_us)

    def set_encoder_ticks(self, left: int, right: int, t_us: int | None = None) -> None:
        """True wheel counts in, slipped counts to the MCU."""
        self.inner.set_encoder_ticks(*self.faults.encoder_ticks(left, right), t_us)

    def set_sonar_provider(self, provider: Callable[[int], float | None] | None) -> None:
        """The plant's sonar ranges, with a failed sonar silent."""
        if provider is None:
            self.inner.set_sonar_provider(None)
            return
        f, mcu = self.faults, self.inner

        def faulted(index: int) -> float | None:
            return f.sonar_range_m(index, provider(index), mcu.now_us)

        self.inner.set_sonar_provider(faulted)


def _quiet_at_coupling(faults: RunFaults) -> bool:
    """True if the plan leaves the MCU's coupling-step calls alone: no MCU reset, host stall,
    crash or line burst (so no recovery points and never a silent host), no failed motor and
    no wheel slip. Faults of the bytes themselves stay on their own (uart_rx, uart_tx_take)."""
    return (faults.mcu_reset_us is None and faults.stall is None and faults.crash_us is None
            and faults.to_mcu.burst is None and faults.to_host.burst is None
            and faults.motor_fail_us is None and faults.slip.keep_q16 == 65536
            and not faults.recovery_points_us())


class FaultedPlant:
    """A plant whose camera frames can be lost or noisy."""

    def __init__(self, plant: Any, faults: RunFaults) -> None:
        self.inner = plant
        self.faults = faults

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)

    def capture(self, t_us: int) -> Any:
        """The frame the CAMIF delivers at ``t_us``, or None when it is lost."""
        rgb = self.inner.capture(t_us)
        return None if rgb is None else self.faults.frame(rgb, t_us)


class FaultRig:
    """The wrappers of one run, their injectors and their monitor."""

    def __init__(self, plan: FaultPlan, seed: int, watchdog_us: int = 250_000) -> None:
        self.faults = RunFaults(plan, seed)
        self.monitor = SafetyMonitor(watchdog_us)
        self.mcu: FaultedMcu | None = None
        self.host_quanta_skipped: Callable[[], int] | None = None  # the host wrapper's count

    def wrap(self, mcu: Any, plant: Any) -> tuple[FaultedMcu, FaultedPlant]:
        """(mcu, plant) wrapped."""
        self.mcu = FaultedMcu(mcu, self.faults, self.monitor)
        return self.mcu, FaultedPlant(plant, self.faults)

    def stop_reason(self, after_crash_us: int = 2_000_000) -> str | None:
        """``"host_crashed"`` once a crashed host's MCU has had ``after_crash_us`` (the 250 ms
        watchdog, with room to spare) to stop safely, else None. A crashed host never comes
        back, so the run ends there instead of idling to its time limit (campaigns of crash
        runs take minutes instead of an hour)."""
        crash = self.faults.crash_us
        if crash is None or self.mcu is None:
            return None
        return "host_crashed" if self.mcu.inner.now_us >= crash + after_crash_us else None

    def summary(self) -> tuple[dict, dict]:
        """(the ``faults`` block, the ``safety`` block) of summary.json."""
        if self.mcu is not None:
            self.monitor.set_limit_hits(self.mcu.inner.limit_hits())
        faults = self.faults.stats()
        if self.mcu is not None:
            faults["mcu_bytes_unread_by_host"] = self.mcu.unread_bytes
        if self.host_quanta_skipped is not None:
            faults["host_quanta_skipped"] = self.host_quanta_skipped()
        return faults, self.monitor.summary()
