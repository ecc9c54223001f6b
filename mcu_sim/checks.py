"""Every value from outside checked once, at the edge: scenario files, ``--fault``, numbers on
command lines, host configurations and campaign rows all go through these checks.

A value is finite, in its range, of its type, and nested no deeper than :data:`MAX_DEPTH`; a
refused value raises :class:`BadValue` (or the caller's subclass of it) with one line: where
(file or option), the key, what was expected, and the value as :func:`shown` prints it, escaped
and cut to :data:`SHOWN_CHARS` characters. A path to read must be a regular file: a FIFO or a
device would block the reader or never end.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import stat
import tomllib
from pathlib import Path
from typing import Any, NoReturn

MAX_DEPTH = 32  # arrays and tables inside one another; the deepest a file of ours needs is 4
SHOWN_CHARS = 60  # of a refused value in an error message
_BIG_INT_BITS = 256  # an integer longer than this is shown by its size, not its digits


class BadValue(ValueError):
    """A value from outside refused: the message is one line naming where, the key and why."""


MISSING = object()  # the key was not given


def depth(value: Any) -> int:
    """How deeply lists, tuples and dicts nest in ``value`` (0: a scalar), without recursion;
    stops counting past MAX_DEPTH + 1."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        node, d = stack.pop()
        if isinstance(node, dict):
            node = list(node.values())
        if isinstance(node, list | tuple):
            deepest = max(deepest, d + 1)
            if deepest > MAX_DEPTH:
                return deepest
            stack.extend((v, d + 1) for v in node)
    return deepest


def shown(value: Any) -> str:
    """``value`` for an error message: Python literal syntax, non-ASCII and control characters
    escaped, at most SHOWN_CHARS characters (a cut ends in ``...``), and never a recursion or
    a conversion of a huge integer."""
    if isinstance(value, int) and not isinstance(value, bool) \
            and value.bit_length() > _BIG_INT_BITS:
        return f"<an integer of {value.bit_length()} bits>"
    if isinstance(value, list | tuple | dict) and depth(value) > 3:
        return f"<a {type(value).__name__} nested {min(depth(value), MAX_DEPTH + 1)}" \
               f"{'+' if depth(value) > MAX_DEPTH else ''} deep>"
    if isinstance(value, str | bytes) and len(value) > 4 * SHOWN_CHARS:
        value = value[:4 * SHOWN_CHARS]
    text = ascii(value)
    return text if len(text) <= SHOWN_CHARS else text[:SHOWN_CHARS - 3] + "..."


_PLAIN_KEY = re.compile(r"[A-Za-z0-9_.\[\]-]{1,60}")


def key_text(key: Any) -> str:
    """A key from outside for an error message: as it is when plain, else :func:`shown`."""
    return key if isinstance(key, str) and _PLAIN_KEY.fullmatch(key) else shown(key)


def fail(where: str, key: str, expected: str, value: Any = MISSING,
         error: type[BadValue] = BadValue) -> NoReturn:
    """Raise ``error``: ``where: key: expected ..., got <value> (<type>)``."""
    got = "" if value is MISSING else f", got {shown(value)} ({type(value).__name__})"
    raise error(f"{where}: {key}: expected {expected}{got}")


def _range(lo: float | None, hi: float | None, unit: str, lo_open: bool = False) -> str:
    def fmt(v: float) -> str:
        return f"{v}" if isinstance(v, int) else f"{v:g}"
    u = f" {unit}" if unit else ""
    if hi is None:
        return f"{'>' if lo_open else '>='} {fmt(lo)}{u}"
    return f"{'(' if lo_open else '['}{fmt(lo)}, {fmt(hi)}]{u}"


def number(value: Any, where: str, key: str, lo: float, hi: float | None, unit: str = "",
           error: type[BadValue] = BadValue, lo_open: bool = False) -> float:
    """A finite int or float in [lo, hi] (``lo_open``: (lo, hi]; ``hi`` None: no top)."""
    rng = _range(lo, hi, unit, lo_open)
    expected = f"a number in {rng}" if hi is not None else f"a number {rng}"
    if isinstance(value, bool) or not isinstance(value, int | float):
        fail(where, key, expected, value, error)
    try:
        v = float(value)
    except OverflowError:  # an integer beyond any float
        fail(where, key, expected, value, error)
    if not math.isfinite(v):
        fail(where, key, f"a finite {expected[2:]}", value, error)
    if v < lo or (lo_open and v == lo) or (hi is not None and v > hi):
        fail(where, key, expected, value, error)
    return v


def arg_number(lo: float, hi: float | None, unit: str = "", lo_open: bool = False):
    """An argparse ``type``: a command-line number checked by :func:`number`."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = text
        try:
            return number(value, "", "", lo, hi, unit, lo_open=lo_open)
        except BadValue as exc:
            raise argparse.ArgumentTypeError(str(exc).split(": expected ", 1)[1]) from None
    return parse


def arg_int(lo: int, hi: int, unit: str = ""):
    """An argparse ``type``: a command-line integer checked by :func:`integer`."""
    def parse(text: str) -> int:
        try:
            value: Any = int(text)
        except ValueError:
            value = text
        try:
            return integer(value, "", "", lo, hi, unit)
        except BadValue as exc:
            raise argparse.ArgumentTypeError(str(exc).split(": expected ", 1)[1]) from None
    return parse


def integer(value: Any, where: str, key: str, lo: int, hi: int, unit: str = "",
            error: type[BadValue] = BadValue) -> int:
    """An int (not a bool) in [lo, hi]."""
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        fail(where, key, f"an integer in {_range(lo, hi, unit)}", value, error)
    return value


def ordered(values: dict, pairs: tuple[tuple[str, str, float], ...], where: str,
            prefix: str = "", error: type[BadValue] = BadValue, given: Any = ()) -> None:
    """Every (lo, hi, gap) of ``pairs`` present in ``values`` has hi - lo >= gap; the key
    named is the one of the pair in ``given`` (what the file set), else ``lo``."""
    for lo, hi, gap in pairs:
        if lo in values and hi in values and values[hi] - values[lo] < gap - 1e-9:
            bad = lo if lo in given or hi not in given else hi
            want = f"{lo} <= {hi}" if not gap else f"{lo} < {hi} by at least {gap:g}"
            raise error(f"{where}: {prefix}{bad}: expected {want}, got {lo} = "
                        f"{shown(values[lo])}, {hi} = {shown(values[hi])}")


def nested(value: Any, where: str, key: str, error: type[BadValue] = BadValue) -> Any:
    """``value`` when it nests at most MAX_DEPTH deep."""
    if depth(value) > MAX_DEPTH:
        fail(where, key, f"a value nested at most {MAX_DEPTH} deep", value, error)
    return value


def read_text(path: str | Path, what: str, error: type[BadValue] = BadValue,
              max_bytes: int = 16 * 1024 * 1024) -> str:
    """The UTF-8 text of a regular file (not a FIFO, device or folder) of at most
    ``max_bytes``; ``error`` naming ``what`` and the path otherwise."""
    p = Path(path)
    try:
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK)  # a FIFO opens without a writer
    except OSError as exc:
        raise error(f"{what} {p}: cannot read it ({exc.strerror or exc})") from exc
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = "a folder" if stat.S_ISDIR(st.st_mode) else "a FIFO" \
                if stat.S_ISFIFO(st.st_mode) else "a device or socket"
            raise error(f"{what} {p}: expected a regular file, got {kind}")
        if st.st_size > max_bytes:
            raise error(f"{what} {p}: expected a file of at most {max_bytes} bytes, got "
                        f"{st.st_size}")
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(max_bytes + 1)
    except OSError as exc:
        raise error(f"{what} {p}: cannot read it ({exc.strerror or exc})") from exc
    finally:
        os.close(fd)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(f"{what} {p}: not UTF-8 text (byte {exc.start}: "
                    f"{data[exc.start:exc.start + 1]!r})") from exc


def load_toml(text: str, where: str, error: type[BadValue] = BadValue) -> dict:
    """TOML text as a dict nested at most MAX_DEPTH deep."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{where}: not valid TOML ({exc})") from exc
    except RecursionError as exc:
        raise error(f"{where}: not valid TOML (nested deeper than {MAX_DEPTH})") from exc
    for k, v in data.items():  # named down to a table's key ("params.k1")
        for k2, v2 in (v.items() if isinstance(v, dict) else [(None, v)]):
            nested(v2, where, key_text(str(k) if k2 is None else f"{k}.{k2}"), error)
    return data


def load_json(text: str, where: str, error: type[BadValue] = BadValue) -> Any:
    """JSON text nested at most MAX_DEPTH deep, without NaN or infinity."""
    def no_constant(name: str) -> None:
        raise error(f"{where}: not valid JSON ({name} is not a number JSON has)")
    try:
        data = json.loads(text, parse_constant=no_constant)
    except RecursionError as exc:
        raise error(f"{where}: not valid JSON (nested deeper than {MAX_DEPTH})") from exc
    except ValueError as exc:
        if isinstance(exc, BadValue):
            raise
        raise error(f"{where}: not valid JSON ({exc})") from exc
    return nested(data, where, "(document)", error)
