"""Watching the Bezier planners: whoever wants every plan the task makes (the calibration's
planner corpus, calib/plan_corpus.py) watches them for a block, without reaching into the task.

A planner decorated with :func:`observed` calls each watcher ``watcher(name, args, kwargs,
plan)`` after it planned; :func:`watching` adds one watcher for a ``with`` block. With nobody
watching a call costs one empty loop; a watcher sees the plan and never changes it.
"""

from __future__ import annotations

import contextlib
import functools
from collections.abc import Callable, Iterator
from typing import Any

Watcher = Callable[[str, tuple, dict, Any], None]
_WATCHERS: list[Watcher] = []


def observed(name: str) -> Callable[[Callable], Callable]:
    """Decorator: the planner ``name`` ("000", "001") tells the watchers of each call."""
    def wrap(fn: Callable) -> Callable:
        @functools.wraps(fn)
        def planner(*args, **kw):
            plan = fn(*args, **kw)
            for watcher in _WATCHERS:
                watcher(name, args, kw, plan)
            return plan
        return planner
    return wrap


@contextlib.contextmanager
def watching(watcher: Watcher) -> Iterator[Watcher]:
    """``watcher`` sees every planner call while the block runs."""
    _WATCHERS.append(watcher)
    try:
        yield watcher
    finally:
        _WATCHERS.remove(watcher)
