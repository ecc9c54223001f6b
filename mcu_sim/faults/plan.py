"""The ``[faults]`` schema of scenario files: :class:`FaultPlan` and its validation.

Keys (docs/faults.md): ``uart_bit_error_rate``, ``uart_drop_rate``, ``uart_latency_us``,
``uart_burst = {start_s, duration_s}``, ``camera_drop_rate``, ``camera_noise_std``,
``host_stall = {at_s, duration_s}``, ``host_crash_at_s``, ``mcu_reset_at_s``,
``motor_fail = {wheel, at_s}``, ``sonar_fail = {index, at_s}``, ``encoder_slip``.

Every problem raises :class:`FaultError` (a ``ValueError``) naming the source, the key and what
was expected; the scenario loader turns it into its ``ScenarioError``. The same checks serve the
command line: :func:`parse_fault_overrides` takes ``KEY=VALUE`` strings (``--fault``), with dotted
keys for the tables (``uart_burst.start_s=3``).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, fields, replace
from typing import Any

from mobigrasp.mcu_sim import checks

WHEELS = ("left", "right")
SONAR_COUNT = 5


class FaultError(checks.BadValue):
    """A fault setting is malformed: the message names the source, the key and the expectation."""


@dataclass(frozen=True)
class Window:
    """A time window of simulated seconds (``uart_burst``: start_s; ``host_stall``: at_s)."""

    start_s: float
    duration_s: float

    def contains_us(self, t_us: int) -> bool:
        """True while ``t_us`` lies in [start, start + duration)."""
        start = round(self.start_s * 1e6)
        return start <= t_us < start + round(self.duration_s * 1e6)


@dataclass(frozen=True)
class MotorFail:
    """``motor_fail``: the ``wheel`` ("left"/"right") motor gives no torque from ``at_s`` on."""

    wheel: str
    at_s: float


@dataclass(frozen=True)
class SonarFail:
    """``sonar_fail``: sonar ``index`` (0..4) never sees an echo from ``at_s`` on."""

    index: int
    at_s: float


@dataclass(frozen=True)
class FaultPlan:
    """The faults of one run; the defaults inject nothing."""

    uart_bit_error_rate: float = 0.0
    uart_drop_rate: float = 0.0
    uart_latency_us: int = 0
    uart_burst: Window | None = None
    camera_drop_rate: float = 0.0
    camera_noise_std: float = 0.0
    host_stall: Window | None = None
    host_crash_at_s: float | None = None
    mcu_reset_at_s: float | None = None
    motor_fail: MotorFail | None = None
    sonar_fail: SonarFail | None = None
    encoder_slip: float = 0.0

    def active(self) -> bool:
        """True if any fault is set."""
        return self != FaultPlan()

    def as_table(self) -> dict[str, Any]:
        """The keys that differ from the defaults, as a TOML/JSON-ready dict."""
        out: dict[str, Any] = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if value == f.default:
                continue
            if isinstance(value, Window):
                key = "start_s" if f.name == "uart_burst" else "at_s"
                value = {key: value.start_s, "duration_s": value.duration_s}
            elif isinstance(value, MotorFail | SonarFail):
                value = dict(vars(value))
            out[f.name] = value
        return out

    def to_toml(self) -> str:
        """A ``[faults]`` section that parses back to this plan ('' when nothing is set)."""
        table = self.as_table()
        if not table:
            return ""
        lines = ["[faults]"]
        for key, value in table.items():
            if isinstance(value, dict):
                inner = ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items())
                lines.append(f"{key} = {{ {inner} }}")
            else:
                lines.append(f"{key} = {_toml_value(value)}")
        return "\n".join(lines) + "\n"


def _toml_value(v: Any) -> str:
    if isinstance(v, str):
        return f'"{v}"'
    return repr(v)


# ---- validation ------------------------------------------------------------------------------
def _fail(source: str, key: str, expected: str, got: Any = None, present: bool = True) -> None:
    checks.fail(source, key, expected, got if present else checks.MISSING, FaultError)


def _number(source: str, key: str, v: Any, lo: float, hi: float | None) -> float:
    return checks.number(v, source, key, lo, hi, error=FaultError)


def _int(source: str, key: str, v: Any, lo: int, hi: int) -> int:
    return checks.integer(v, source, key, lo, hi, error=FaultError)


def _table(source: str, key: str, v: Any, spec: dict[str, Any]) -> dict[str, Any]:
    names = ", ".join(spec)
    if not isinstance(v, dict):
        _fail(source, key, f"a table with {names}", v)
    for k in v:
        if k not in spec:
            raise FaultError(f"{source}: {checks.key_text(f'{key}.{k}')}: unknown key; "
                             f"expected one of: {names}")
    out = {}
    for k, check in spec.items():
        if k not in v:
            _fail(source, f"{key}.{k}", "a value (missing)", present=False)
        out[k] = check(f"{key}.{k}", v[k])
    return out


def _wheel(source: str, key: str, v: Any) -> str:
    if v not in WHEELS:
        _fail(source, key, 'one of "left", "right"', v)
    return v


_MAX_S = 1e6  # a time beyond any run; keeps the µs conversions in range


def _checkers(source: str) -> dict[str, Any]:
    def rate(k, v):
        return _number(source, k, v, 0.0, 1.0)

    def secs(k, v):
        return _number(source, k, v, 0.0, _MAX_S)

    def window(first):
        def check(k, v):
            t = _table(source, k, v, {first: secs, "duration_s": secs})
            return Window(t[first], t["duration_s"])
        return check

    def motor(k, v):
        t = _table(source, k, v, {"wheel": lambda kk, vv: _wheel(source, kk, vv),
                                  "at_s": secs})
        return MotorFail(t["wheel"], t["at_s"])

    def sonar(k, v):
        t = _table(source, k, v, {"index": lambda kk, vv: _int(source, kk, vv, 0,
                                                               SONAR_COUNT - 1),
                                  "at_s": secs})
        return SonarFail(t["index"], t["at_s"])

    return {
        "uart_bit_error_rate": lambda k, v: _number(source, k, v, 0.0, 0.5),
        "uart_drop_rate": rate,
        "uart_latency_us": lambda k, v: _int(source, k, v, 0, 10_000_000),
        "uart_burst": window("start_s"),
        "camera_drop_rate": rate,
        "camera_noise_std": lambda k, v: _number(source, k, v, 0.0, 255.0),
        "host_stall": window("at_s"),
        "host_crash_at_s": secs,
        "mcu_reset_at_s": secs,
        "motor_fail": motor,
        "sonar_fail": sonar,
        "encoder_slip": lambda k, v: _number(source, k, v, 0.0, 1.0),
    }


FAULT_KEYS: tuple[str, ...] = tuple(f.name for f in fields(FaultPlan))


def parse_faults(table: Any, source: str = "<faults>", base: FaultPlan | None = None,
                 where: str = "faults") -> FaultPlan:
    """Validate a ``[faults]`` table (as read from TOML) into a :class:`FaultPlan`.

    Keys not in the table keep their value in ``base`` (default: no fault)."""
    if not isinstance(table, dict):
        _fail(source, where, "a table (section)", table)
    checkers = _checkers(source)
    values: dict[str, Any] = {}
    for key, value in table.items():
        if key not in checkers:
            raise FaultError(f"{source}: {checks.key_text(f'{where}.{key}')}: unknown key; "
                             f"expected one of: {', '.join(FAULT_KEYS)}")
        values[key] = checkers[key](f"{where}.{key}", value)
    return replace(base or FaultPlan(), **values)


def _parse_value(text: str) -> Any:
    """A command-line value: a TOML scalar (3, 1e-3, "left", true), or the bare word itself."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except (tomllib.TOMLDecodeError, RecursionError):
        return text


def parse_fault_overrides(items: list[str] | tuple[str, ...], base: FaultPlan | None = None,
                          source: str = "--fault") -> FaultPlan:
    """Apply ``KEY=VALUE`` strings (``--fault``) to ``base``; dotted keys set table fields.

    A dotted key may set one field of a table the base already has (``uart_burst.duration_s=2``
    after a scenario set the burst); otherwise every field of the table must be given."""
    base = base or FaultPlan()
    current = base.as_table()
    table: dict[str, Any] = {}
    for item in items:
        if not isinstance(item, str) or "=" not in item:
            raise FaultError(f"{source}: {checks.shown(item)}: expected KEY=VALUE (e.g. "
                             f"uart_bit_error_rate=1e-3 or uart_burst.start_s=3)")
        key, _, text = item.partition("=")
        key, text = key.strip(), text.strip()
        if not key or not text:
            raise FaultError(f"{source}: {checks.shown(item)}: expected KEY=VALUE with both "
                             f"parts")
        value = _parse_value(text)
        if "." in key:
            outer, _, inner = key.partition(".")
            if outer not in FAULT_KEYS:
                raise FaultError(f"{source}: {checks.key_text(f'faults.{outer}')}: unknown key; "
                                 f"expected one of: {', '.join(FAULT_KEYS)}")
            sub = table.get(outer)
            if not isinstance(sub, dict):
                sub = dict(current.get(outer, {})) if isinstance(current.get(outer), dict) else {}
            sub[inner] = value
            table[outer] = sub
        else:
            table[key] = value
    return parse_faults(table, source, base)
