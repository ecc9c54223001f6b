"""Watching the Bezier planners: whoever wants every plan the task makes (the calibration's
planner corpus, calib/plan_corpus.py) watches them for a block, without reaching into the task.

A planner decorated with :func:`observed` calls each watcher ``watcher(name, args, kwargs,
plan)`` after it planned; :func:`watching` adds one watcher for a ``with`` block. With nobody
watching a call costs one empty loop; a watcher sees the plan and never changes it. Topics
keep watchers apart: "plan" (the planners, the default) and "replan" (001's replanner's
``start``, ``update`` and ``start_path``, by those names; ``args[0]`` is the replanner, its
state after the call).
"""

from __future__ import annotations

import contextlib
import functools
from collections.abc import Callable, Iterator
from typing import Any

Watcher = Callable[[str, tuple, dict, Any], None]
_WATCHERS: dict[str, list[Watcher]] = {"plan": [], "replan": []}


def observed(name: str, topic: str = "plan") -> Callable[[Callable], Callable]:
    """Decorator: the planner ``name`` ("000", "001") tells the watchers of ``topic`` of each
    call."""
    watchers = _WATCHERS[topic]

    def wrap(fn: Callable) -> Callable:
        @functools.wraps(fn)
        def planner(*args, **kw):
            plan = fn(*args, **kw)
            for watcher in watchers:
                watcher(name, args, kw, plan)
            return plan
        return planner
    return wrap


@contextlib.contextmanager
def watching(watcher: Watcher, topic: str = "plan") -> Iterator[Watcher]:
    """``watcher`` sees every call of ``topic`` while the block runs."""
    _WATCHERS[topic].append(watcher)
    try:
        yield watcher
    finally:
        _WATCHERS[topic].remove(watcher)
