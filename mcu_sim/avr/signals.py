"""Named signal ports of the emulated ATmega128, in the manner of simavr's IRQ ports.

A port carries a stream of ``(t_us, value)`` samples. Peripheral models ``emit`` on it; the world,
the rig and tests ``subscribe`` a callback. Edges of the servo outputs are stamped in simulated
microseconds as an integer ``t_us`` plus the exact 16 MHz cycle in ``last_cycle`` (a 0.5 µs timer
tick is not a whole microsecond), so a subscriber that needs sub-microsecond precision reads the
cycle while a simple one uses ``t_us``.
"""

from __future__ import annotations

from collections.abc import Callable

Callback = Callable[[int, int], None]


class SignalPort:
    """One named output: the latest value, its time, and subscribers called on every change."""

    __slots__ = ("name", "value", "t_us", "last_cycle", "subscribers")

    def __init__(self, name: str, value: int = 0) -> None:
        self.name = name
        self.value = int(value)
        self.t_us = 0
        self.last_cycle = 0
        self.subscribers: list[Callback] = []

    def subscribe(self, callback: Callback) -> Callable[[], None]:
        """Call ``callback(t_us, value)`` on every sample; returns an unsubscribe function."""
        if not callable(callback):
            raise TypeError(f"signal {self.name}: callback must be callable, got {callback!r}")
        self.subscribers.append(callback)

        def unsubscribe() -> None:
            if callback in self.subscribers:
                self.subscribers.remove(callback)

        return unsubscribe

    def emit(self, cycle: int, value: int, cycles_per_us: int = 16) -> None:
        """Record ``value`` at CPU cycle ``cycle`` and notify subscribers with the time in µs."""
        self.value = value
        self.last_cycle = cycle
        self.t_us = cycle // cycles_per_us
        for callback in self.subscribers:
            callback(self.t_us, value)


class SignalBus:
    """The set of named ports of one MCU, created on first use so wiring order does not matter."""

    def __init__(self) -> None:
        self._ports: dict[str, SignalPort] = {}

    def port(self, name: str) -> SignalPort:
        """The port called ``name`` (created if new)."""
        port = self._ports.get(name)
        if port is None:
            port = SignalPort(name)
            self._ports[name] = port
        return port

    def names(self) -> list[str]:
        """Names of all ports created so far, sorted."""
        return sorted(self._ports)
