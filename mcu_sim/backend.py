"""The MCU as the rig, ``mobigrasp mcu``, the pytest fixture and the benches drive it: one
interface, and the registry of its backends by name.

A backend is a factory ``(config) -> McuBackend`` in :data:`MCU_BACKENDS`; :func:`open_mcu`
opens one by name and rejects an unknown name by name. ``python`` is the firmware model on the
Python peripherals (mobigrasp.mcu_sim.mcu.Mcu), ``native`` the C firmware (``firmware/``) built
for this machine on the same peripherals (mobigrasp.mcu_sim.native), ``simavr`` the avr-gcc
ELF of that firmware on simavr's instruction-accurate core (mobigrasp.mcu_sim.simavr). Every
backend passes
tests/contract/test_mcu_contract.py
(with the fault wrapper and the test fakes).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

from mobigrasp.mcu_sim.mcu import Mcu, McuConfig


class McuBackend(Protocol):
    """One emulated ATmega128 running the mobigrasp firmware, moved by the caller's clock."""

    @property
    def now_us(self) -> int:
        """Current simulated time in µs."""

    def advance_to(self, t_us: int) -> None:
        """Run until simulated time ``t_us`` (events at exactly ``t_us`` included)."""

    def advance_outputs(self, t_us: int) -> tuple[tuple[float, ...], tuple[int, int]]:
        """:meth:`advance_to`, then (:meth:`servo_pulses_us`, :meth:`wheel_duty`): the rig's
        coupling step in one call."""

    def reset(self) -> None:
        """A power-on reset at the current time (RAM and peripherals as after power-up)."""

    def uart_rx(self, data: bytes, start_us: int | None = None) -> int:
        """Host bytes onto the RX line from ``start_us`` (default now) at the line's baud;
        how many were accepted."""

    def uart_tx_take(self) -> list[tuple[int, bytes]]:
        """The chunks (time their stop bit left, bytes) sent since the last call."""

    def tx_idle_through_us(self) -> int | None:
        """A time up to which the MCU certainly sends no byte (None: cannot tell)."""

    @property
    def baud(self) -> float:
        """The UART's actual baud rate."""

    @property
    def baud_error_pct(self) -> float:
        """Its error against the nominal 115200, in percent."""

    def servo_pulse_us(self, ch: int) -> float:
        """Width of the last complete pulse on servo channel ``ch`` (0 before the first)."""

    def servo_pulses_us(self) -> tuple[float, ...]:
        """The six servo pulse widths at once."""

    def wheel_duty(self) -> tuple[int, int]:
        """Signed 8-bit PWM duties (left, right) that reach the motors."""

    def set_encoder_ticks(self, left: int, right: int, t_us: int | None = None) -> None:
        """Cumulative quadrature counts of the two wheels at ``t_us`` (default now)."""

    def set_sonar_provider(self, provider: Callable[[int], float | None] | None) -> None:
        """Where sonar ``index``'s range in metres comes from (None: no echo)."""

    def safety_flags(self) -> tuple[bool, bool]:
        """(watchdog stop active, host handshake done): what the safety monitor judges."""

    def limit_hits(self) -> int:
        """Commands the firmware had to clamp to the joint limits so far."""

    def stats(self) -> dict[str, int]:
        """Counters for the run's summary (parser errors, watchdog trips, ...)."""


def _python(config: McuConfig | None = None) -> McuBackend:
    return Mcu(config)


def _native(config: McuConfig | None = None) -> McuBackend:
    # imported on first use: it compiles the C firmware once per source hash
    from mobigrasp.mcu_sim.native.mcu import NativeMcu
    return NativeMcu(config)


def _simavr(config: McuConfig | None = None) -> McuBackend:
    # imported on first use: it builds the avr-gcc ELF and the libsimavr harness once per hash
    from mobigrasp.mcu_sim.simavr.mcu import SimavrMcu
    return SimavrMcu(config)


# name -> factory(config); a plain dict: a backend module adds its own entry
MCU_BACKENDS: dict[str, Callable[..., McuBackend]] = {"python": _python, "native": _native,
                                                      "simavr": _simavr}


class UnknownBackend(ValueError):
    """An MCU backend name that is not registered."""


def open_mcu(name: str = "python", config: Any = None) -> McuBackend:
    """A new MCU of backend ``name``; UnknownBackend naming it and the known ones otherwise."""
    factory = MCU_BACKENDS.get(name)
    if factory is None:
        known = ", ".join(sorted(MCU_BACKENDS))
        raise UnknownBackend(f"unknown MCU backend {name!r} (known: {known})")
    return factory(config)
