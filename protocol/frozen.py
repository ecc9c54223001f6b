"""Frozen dataclass instances built without their generated ``__init__``: the one speed shortcut
for the hot paths that build one per quantum, per received frame or per control tick.

A frozen dataclass's ``__init__`` sets each field through ``object.__setattr__`` (the freeze) and
runs ``__post_init__``; :func:`built` fills the instance's ``__dict__`` at once. It is for a class
without ``__post_init__``, or one whose checks the caller has already made on trusted values,
with every field given; tests/unit/protocol/test_frozen.py checks that the result equals the
constructor's for each class it is used on. Stdlib only, in the lowest room, so every room may
use it.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any, TypeVar

T = TypeVar("T")


def built(cls: type[T], pairs: Iterable[tuple[str, Any]] = (), /, **fields: Any) -> T:
    """An instance of the frozen dataclass ``cls`` with its fields from ``pairs`` and
    ``fields``, all of them given, built without ``__init__`` (nor ``__post_init__``)."""
    obj = object.__new__(cls)
    d = obj.__dict__
    if pairs:
        d.update(pairs)
    d.update(fields)
    return obj
