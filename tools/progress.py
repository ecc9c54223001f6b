"""Progress and diagnostics of every ``mobigrasp`` command, in one place.

- :func:`add_common_options` gives a parser ``-v/--verbose`` (repeatable) and ``-q/--quiet``;
  the CLI adds them to every subcommand and :func:`setup_logging` maps them onto the stdlib
  ``logging`` levels of the ``mobigrasp`` logger (WARNING by default, INFO with -v, DEBUG with
  -vv, ERROR only with -q). Diagnostics go through ``logging.getLogger(__name__)``; results a
  command exists to print (tables, summary lines) stay on stdout.
- :class:`Progress` is a bar (tqdm) when its stream is a terminal and a plain line every
  ``interval_s`` wall seconds otherwise, so a piped log holds whole lines and no carriage
  returns; it prints nothing when disabled. Wall time here is for display only, never a result.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
import time
from collections.abc import Callable
from typing import TextIO

LOGGER_NAME = "mobigrasp"
PLAIN_INTERVAL_S = 5.0  # plain-line progress: one line per this many wall seconds
# ... unless this environment variable gives another interval (seconds >= 0; 0: every update,
# for a program that follows a run's progress line by line)
INTERVAL_ENV = "MOBIGRASP_PROGRESS_INTERVAL_S"


def plain_interval_s() -> float:
    """Seconds between plain progress lines: $MOBIGRASP_PROGRESS_INTERVAL_S, else 5."""
    text = os.environ.get(INTERVAL_ENV)
    if text is None:
        return PLAIN_INTERVAL_S
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0.0 <= value <= 3600.0:
        logging.getLogger(LOGGER_NAME).warning("%s=%r is not a number of seconds in [0, 3600]; "
                                               "using %g", INTERVAL_ENV, text, PLAIN_INTERVAL_S)
        return PLAIN_INTERVAL_S
    return value


def add_common_options(parser: argparse.ArgumentParser) -> None:
    """``-v/--verbose`` and ``-q/--quiet`` on ``parser`` (every subcommand has them)."""
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="more diagnostics on stderr (-v: info, -vv: debug)")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="no progress display and only errors on stderr")


def log_level(verbose: int = 0, quiet: bool = False) -> int:
    """The ``logging`` level of the flags: ERROR when quiet, else WARNING/INFO/DEBUG."""
    if quiet:
        return logging.ERROR
    return {0: logging.WARNING, 1: logging.INFO}.get(verbose, logging.DEBUG)


class _CommandHandler(logging.StreamHandler):
    """The stderr handler :func:`setup_logging` installs (and replaces on a second call)."""


def setup_logging(verbose: int = 0, quiet: bool = False, stream: TextIO | None = None) -> None:
    """Send the ``mobigrasp`` logger's records to ``stream`` (stderr) at the flags' level;
    calling it again replaces the handler (one per process)."""
    logger = logging.getLogger(LOGGER_NAME)
    for handler in list(logger.handlers):
        if isinstance(handler, _CommandHandler):
            logger.removeHandler(handler)
    handler = _CommandHandler(stream if stream is not None else sys.stderr)
    handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    logger.addHandler(handler)
    logger.setLevel(log_level(verbose, quiet))
    logger.propagate = False


def is_terminal(stream: TextIO | None) -> bool:
    """True when ``stream`` is an interactive terminal."""
    isatty = getattr(stream, "isatty", None)
    try:
        return bool(isatty and isatty())
    except ValueError:  # a closed stream
        return False


class Progress:
    """Progress of ``total`` items (None: unknown) on ``stream`` (default stderr).

    ``update(done, text)`` sets the count reached and a short status text. On a terminal it
    drives a tqdm bar; elsewhere it writes ``desc: done/total text`` at most once per
    ``interval_s`` wall seconds (and once at :meth:`close`). ``enabled=False`` prints nothing."""

    def __init__(self, total: float | None = None, desc: str = "", unit: str = "it",
                 stream: TextIO | None = None, enabled: bool = True,
                 interval_s: float | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.total, self.desc, self.unit = total, desc, unit
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        self.interval_s = plain_interval_s() if interval_s is None else interval_s
        self.clock = clock
        self.done: float = 0
        self.text = ""
        self.lines = 0  # plain lines written
        self._bar = None
        self._next_line = None
        self._closed = False
        self._terminal = enabled and is_terminal(self.stream)

    @property
    def bar(self) -> bool:
        """True when it draws a terminal bar (False: plain lines or nothing)."""
        return self._terminal

    def update(self, done: float, text: str = "") -> None:
        """The count reached so far and a short status text."""
        if not self.enabled or self._closed:
            return
        step = done - self.done
        self.done, self.text = done, text
        if self._terminal:
            if self._bar is None:  # made at the first update: nothing shows for bad input
                from tqdm import tqdm

                self._bar = tqdm(total=self.total, desc=self.desc, unit=self.unit,
                                 file=self.stream, dynamic_ncols=True, leave=True)
            if text:
                self._bar.set_postfix_str(text, refresh=False)
            self._bar.update(step)
            return
        now = self.clock()
        if self._next_line is None:
            self._next_line = now + self.interval_s  # no line for a run shorter than that
        elif now >= self._next_line:
            self._line()
            self._next_line = now + self.interval_s

    def _line(self) -> None:
        count = f"{self.done:g}" + (f"/{self.total:g}" if self.total is not None else "")
        head = f"{self.desc}: " if self.desc else ""
        self.stream.write(f"{head}{count} {self.unit}{'  ' + self.text if self.text else ''}\n")
        self.stream.flush()
        self.lines += 1

    def close(self) -> None:
        """End the display: the bar is left complete, a last plain line says where it ended."""
        if self._closed:
            return
        self._closed = True
        if self._bar is not None:
            self._bar.close()
        elif self.enabled and self._next_line is not None:
            self._line()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class RunProgress(Progress):
    """Progress of one closed-loop run: simulated seconds reached, task state and the
    simulated/wall time factor. Called as ``progress(now_us, state, wall_s)``."""

    def __init__(self, total_s: float | None = None, **kw) -> None:
        super().__init__(total=total_s, desc=kw.pop("desc", "run"), unit="s simulated", **kw)

    def __call__(self, now_us: int, state: str, wall_s: float) -> None:
        rtf = now_us / 1e6 / wall_s if wall_s > 0 else 0.0
        self.update(round(now_us / 1e6, 2), f"state={state} rtf={rtf:.1f}x")

    def finish(self, summary: dict | None) -> None:
        """Show where the run ended (from its summary.json dict) and close the display."""
        if summary:
            self(int(1e6 * (summary.get("sim_time_s") or 0)), str(summary.get("task_state")),
                 float(summary.get("wall_time_s") or 0.0))
        self.close()


class StepProgress(Progress):
    """Progress of a job of counted steps whose total may be known only once it started
    (``calibrate``: scenarios recorded, then frames and planner calls emulated). Called as
    ``progress(done, total, what)``: the count, ``what`` the step just done, the wall time
    elapsed since the display was made and the time left at the mean pace so far, as the bench
    loop shows them (mobigrasp.services.time_left)."""

    def __init__(self, desc: str, unit: str, **kw) -> None:
        super().__init__(total=None, desc=desc, unit=unit, **kw)
        self._start = self.clock()

    def __call__(self, done: int, total: int, what: str = "") -> None:
        from mobigrasp.services.time_left import elapsed_left

        if total != self.total:
            self.total = total
            if self._bar is not None:
                self._bar.total = total
        text = elapsed_left(self.clock() - self._start, done, total - done)
        self.update(done, f"{what}, {text}" if what else text)
