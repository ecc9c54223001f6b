"""Elapsed wall time and the time left of a job of counted steps, as the progress displays of
the bench loop, campaigns and ``calibrate`` show them ("elapsed 1m05s, ~3m20s left"). Wall time
is for display only, never a result."""

from __future__ import annotations


def clock_text(s: float) -> str:
    """``1m05s``, or ``1h02m`` from an hour on."""
    s = int(round(s))
    return f"{s // 3600}h{s // 60 % 60:02d}m" if s >= 3600 else f"{s // 60}m{s % 60:02d}s"


def elapsed_left(elapsed_s: float, done_here: int, left: int) -> str:
    """``elapsed X``, and ``, ~Y left`` once a step was done here and some are left: the
    steps left at the mean time of the ``done_here`` steps done in ``elapsed_s``."""
    text = f"elapsed {clock_text(elapsed_s)}"
    if done_here > 0 and left > 0:
        text += f", ~{clock_text(elapsed_s / done_here * left)} left"
    return text
