"""``expect``: advance a clock in steps until a condition holds (Renode's ``Wait For Line On
Uart``, Wokwi's ``--expect-text`` with a timeout in simulated ms).

The clock is the caller's: ``advance_ms`` moves it, so the deadline is simulated time and the
outcome is the same on any machine. ``between`` runs before every step (one iteration of the
host loop under test, so the host keeps talking while the test waits). On failure the error
says what ``seen()`` returned last.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


class ExpectationFailed(AssertionError):
    """The condition did not hold within the time given; the message says what was seen."""


def expect(predicate: Callable[[], bool], within_ms: int, advance_ms: Callable[[int], None],
           seen: Callable[[], Any], step_ms: int = 1,
           between: Callable[[], None] | None = None) -> int:
    """Check ``predicate()``, then alternate ``between()``, ``advance_ms(step_ms)`` and the check
    until it holds; the simulated ms it took. Raises ExpectationFailed after ``within_ms``."""
    if not (isinstance(within_ms, int) and within_ms >= 0):
        raise ValueError(f"within_ms must be an integer >= 0, got {within_ms!r}")
    if not (isinstance(step_ms, int) and step_ms > 0):
        raise ValueError(f"step_ms must be a positive integer, got {step_ms!r}")
    waited = 0
    while not predicate():
        if waited >= within_ms:
            raise ExpectationFailed(f"not true within {within_ms} ms of simulated time; "
                                    f"last seen: {seen()}")
        if between is not None:
            between()
        step = min(step_ms, within_ms - waited)
        advance_ms(step)
        waited += step
    return waited
