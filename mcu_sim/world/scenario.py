"""Scenario files: TOML (tomllib) loading and strict validation into frozen dataclasses.

Contract (issue 5): ``[scenario]`` name, method ("000"/"001"/"002"), seed, time_limit_s;
``[robot]`` x_m, y_m, heading_rad; ``[target]`` kind, x_m, y_m, heading_rad and optional
``[[target.path]]`` t_s, x_m, y_m; ``[[obstacles]]`` shape "circle" (radius_m) or "box"
(width_m, depth_m, heading_rad), or "wall" (x2_m, y2_m, optional thickness_m), each with an
optional height_m; ``[camera]`` optional f_px, u0_px, v0_px, noise_std, blur_px, brightness;
``[params]`` overrides of the method's paper parameters (names and defaults in
:data:`PAPER_PARAMS`); ``[faults]`` the injected faults, validated into a
:class:`mobigrasp.mcu_sim.faults.plan.FaultPlan` (keys in docs/faults.md).

Every problem raises :class:`ScenarioError` naming the file, the key and what was expected.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from mobigrasp.mcu_sim.faults.plan import FaultError, FaultPlan, parse_faults

METHODS = ("000", "001", "002")
TARGET_KINDS = ("radial-symbol", "double-cross", "red-cylinder")
OBSTACLE_SHAPES = ("circle", "box", "wall")
DEFAULT_OBSTACLE_HEIGHT_M = 0.30
DEFAULT_WALL_THICKNESS_M = 0.05

# Paper parameters per method, with the papers' values (section IV of 000 and 001, section 5 of
# 002). Type int means the value must be an integer; float accepts int or float.
PAPER_PARAMS: dict[str, dict[str, tuple[type, float]]] = {
    "000": {
        "k_s": (int, 5), "T_s": (float, 0.3), "k1": (float, 0.5), "k2": (float, 0.5),
        "theta2_min": (float, -2.8), "theta2_max": (float, -2.1),
        "theta5_min": (float, -0.8), "theta5_max": (float, 0.8),
        "dtheta2_l": (float, 0.06), "k_theta2": (float, 1.0), "k_theta3": (float, 0.0),
        "k_theta4": (float, 0.0), "alpha_T": (float, -math.pi / 2),
        "w_min": (int, 20), "w_max": (int, 40),
        "v0_mps": (float, 0.12), "vmax_mps": (float, 0.25), "amax_mps2": (float, 0.04),
        "rmin_m": (float, 0.1), "l_w": (float, 0.3), "L_m": (float, 0.109),
        "D_act_m": (float, 0.0473),
    },
    "001": {
        "Vmax": (float, 0.4), "Amax": (float, 0.1), "R_r": (float, 0.2), "k_s": (int, 5),
        "A_g": (float, 1.05), "D_e": (float, 2.5), "h_e": (float, 0.208), "n_e": (int, 36),
        "v0": (float, 0.2), "T_s": (float, 0.5), "k1": (float, 0.8), "k2": (float, 0.2),
        "T_D": (float, 15.0),
    },
    "002": {
        "T_h": (int, 30), "n": (int, 10), "e_th": (float, 1.43), "e_cth": (float, 5.0),
        "u_th": (float, 1.0), "V_avg": (float, 0.15), "k_u": (float, 1.0),
        "D": (float, 0.0145), "T_d": (float, 45.0),
    },
}

# Camera intrinsics per method (000: f = 611 px; 002: f = 350 px, (u0, v0) = (160, 120)).
CAMERA_DEFAULTS: dict[str, dict[str, float]] = {
    "000": {"f_px": 611.0, "u0_px": 160.0, "v0_px": 120.0},
    "001": {"f_px": 611.0, "u0_px": 160.0, "v0_px": 120.0},
    "002": {"f_px": 350.0, "u0_px": 160.0, "v0_px": 120.0},
}


class ScenarioError(ValueError):
    """A scenario file is malformed: the message names the file, the key and what was expected."""


@dataclass(frozen=True)
class ScenarioMeta:
    """``[scenario]``."""

    name: str
    method: str
    seed: int
    time_limit_s: float


@dataclass(frozen=True)
class RobotStart:
    """``[robot]``: start pose of the base (wheel-axle midpoint) in the world frame."""

    x_m: float
    y_m: float
    heading_rad: float


@dataclass(frozen=True)
class PathPoint:
    """One ``[[target.path]]`` way point: the target is at (x_m, y_m) at time t_s."""

    t_s: float
    x_m: float
    y_m: float


@dataclass(frozen=True)
class TargetSpec:
    """``[target]``."""

    kind: str
    x_m: float
    y_m: float
    heading_rad: float
    path: tuple[PathPoint, ...] = ()


@dataclass(frozen=True)
class ObstacleSpec:
    """One ``[[obstacles]]`` entry (fields not used by the shape are None)."""

    shape: str
    x_m: float
    y_m: float
    radius_m: float | None = None
    width_m: float | None = None
    depth_m: float | None = None
    heading_rad: float = 0.0
    x2_m: float | None = None
    y2_m: float | None = None
    thickness_m: float | None = None
    height_m: float = DEFAULT_OBSTACLE_HEIGHT_M


@dataclass(frozen=True)
class CameraSpec:
    """``[camera]`` with the method's intrinsics filled in."""

    f_px: float
    u0_px: float
    v0_px: float
    noise_std: float = 0.0
    blur_px: float = 0.0
    brightness: float = 1.0


@dataclass(frozen=True)
class Scenario:
    """A validated scenario (read-only).

    ``params`` holds every paper parameter of the method (paper defaults, then the file's
    ``[params]``); ``param_overrides`` only the keys the file itself set.
    """

    source: str
    meta: ScenarioMeta
    robot: RobotStart
    target: TargetSpec
    obstacles: tuple[ObstacleSpec, ...]
    camera: CameraSpec
    params: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    faults: FaultPlan = field(default_factory=FaultPlan)
    param_overrides: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario file."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise ScenarioError(f"{p}: cannot read scenario file ({exc.strerror})") from exc
    return loads_scenario(text, source=str(p))


def loads_scenario(text: str, source: str = "<string>") -> Scenario:
    """Parse and validate scenario TOML text; ``source`` names it in error messages."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{source}: not valid TOML ({exc})") from exc
    return parse_scenario(data, source)


class _Checker:
    """Typed field access with errors naming file, key and expectation."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, key: str, expected: str, got: Any = None, present: bool = True) -> None:
        got_txt = f", got {got!r} ({type(got).__name__})" if present else ""
        raise ScenarioError(f"{self.source}: {key}: expected {expected}{got_txt}")

    def table(self, data: dict, key: str, required: bool = True) -> dict | None:
        if key not in data:
            if required:
                self.fail(key, "a table (section)", present=False)
            return None
        value = data[key]
        if not isinstance(value, dict):
            self.fail(key, "a table (section)", value)
        return value

    def keys(self, table: dict, where: str, allowed: tuple[str, ...]) -> None:
        for k in table:
            if k not in allowed:
                name = f"{where}.{k}" if where else k
                raise ScenarioError(f"{self.source}: {name}: unknown key; expected one of: "
                                    f"{', '.join(allowed)}")

    def number(self, table: dict, where: str, key: str, default: float | None = None,
               required: bool = True, positive: bool = False, nonneg: bool = False) -> Any:
        name = f"{where}.{key}"
        if key not in table:
            if required:
                self.fail(name, "a number (missing)", present=False)
            return default
        v = table[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            self.fail(name, "a number", v)
        v = float(v)
        if not math.isfinite(v):
            self.fail(name, "a finite number", v)
        if positive and v <= 0:
            self.fail(name, "a number > 0", v)
        if nonneg and v < 0:
            self.fail(name, "a number >= 0", v)
        return v

    def integer(self, table: dict, where: str, key: str) -> int:
        name = f"{where}.{key}"
        if key not in table:
            self.fail(name, "an integer (missing)", present=False)
        v = table[key]
        if isinstance(v, bool) or not isinstance(v, int):
            self.fail(name, "an integer", v)
        return v

    def choice(self, table: dict, where: str, key: str, options: tuple[str, ...]) -> str:
        name = f"{where}.{key}"
        expected = "one of " + ", ".join(f'"{o}"' for o in options)
        if key not in table:
            self.fail(name, f"{expected} (missing)", present=False)
        v = table[key]
        if not isinstance(v, str) or v not in options:
            self.fail(name, expected, v)
        return v


def parse_scenario(data: dict, source: str = "<dict>") -> Scenario:
    """Validate an already-parsed TOML document."""
    c = _Checker(source)
    c.keys(data, "", ("scenario", "robot", "target", "obstacles", "camera", "params", "faults"))

    s = c.table(data, "scenario")
    c.keys(s, "scenario", ("name", "method", "seed", "time_limit_s"))
    if "name" not in s or not isinstance(s["name"], str) or not s["name"]:
        c.fail("scenario.name", "a non-empty string", s.get("name"), present="name" in s)
    method = c.choice(s, "scenario", "method", METHODS)
    seed = c.integer(s, "scenario", "seed")
    if seed < 0:
        c.fail("scenario.seed", "an integer >= 0", seed)
    meta = ScenarioMeta(s["name"], method, seed,
                        c.number(s, "scenario", "time_limit_s", positive=True))

    r = c.table(data, "robot")
    c.keys(r, "robot", ("x_m", "y_m", "heading_rad"))
    robot = RobotStart(c.number(r, "robot", "x_m"), c.number(r, "robot", "y_m"),
                       c.number(r, "robot", "heading_rad"))

    target = _parse_target(c, c.table(data, "target"))
    obstacles = _parse_obstacles(c, data.get("obstacles", []))
    camera = _parse_camera(c, c.table(data, "camera", required=False) or {}, method)
    raw_params = c.table(data, "params", required=False) or {}
    params = _parse_params(c, raw_params, method)
    faults_table = c.table(data, "faults", required=False) or {}
    try:
        faults = parse_faults(faults_table, source)
    except FaultError as exc:
        raise ScenarioError(str(exc)) from exc
    overrides = {k: params[k] for k in raw_params}
    return Scenario(source, meta, robot, target, obstacles, camera,
                    MappingProxyType(params), faults,
                    MappingProxyType(overrides))


def _parse_target(c: _Checker, t: dict) -> TargetSpec:
    c.keys(t, "target", ("kind", "x_m", "y_m", "heading_rad", "path"))
    kind = c.choice(t, "target", "kind", TARGET_KINDS)
    raw_path = t.get("path", [])
    if not isinstance(raw_path, list):
        c.fail("target.path", "an array of tables [[target.path]]", raw_path)
    path: list[PathPoint] = []
    for i, entry in enumerate(raw_path):
        where = f"target.path[{i}]"
        if not isinstance(entry, dict):
            c.fail(where, "a table with t_s, x_m, y_m", entry)
        c.keys(entry, where, ("t_s", "x_m", "y_m"))
        pt = PathPoint(c.number(entry, where, "t_s", nonneg=True),
                       c.number(entry, where, "x_m"), c.number(entry, where, "y_m"))
        if path and pt.t_s <= path[-1].t_s:
            c.fail(f"{where}.t_s", f"a time later than {path[-1].t_s} s (strictly increasing)",
                   pt.t_s)
        path.append(pt)
    return TargetSpec(kind, c.number(t, "target", "x_m"), c.number(t, "target", "y_m"),
                      c.number(t, "target", "heading_rad"), tuple(path))


def _parse_obstacles(c: _Checker, raw: Any) -> tuple[ObstacleSpec, ...]:
    if not isinstance(raw, list):
        c.fail("obstacles", "an array of tables [[obstacles]]", raw)
    out = []
    for i, o in enumerate(raw):
        where = f"obstacles[{i}]"
        if not isinstance(o, dict):
            c.fail(where, "a table", o)
        shape = c.choice(o, where, "shape", OBSTACLE_SHAPES)
        common = ("shape", "x_m", "y_m", "height_m")
        x, y = c.number(o, where, "x_m"), c.number(o, where, "y_m")
        h = c.number(o, where, "height_m", DEFAULT_OBSTACLE_HEIGHT_M, required=False,
                     positive=True)
        if shape == "circle":
            c.keys(o, where, common + ("radius_m",))
            out.append(ObstacleSpec(shape, x, y, radius_m=c.number(o, where, "radius_m",
                                                                   positive=True), height_m=h))
        elif shape == "box":
            c.keys(o, where, common + ("width_m", "depth_m", "heading_rad"))
            out.append(ObstacleSpec(shape, x, y,
                                    width_m=c.number(o, where, "width_m", positive=True),
                                    depth_m=c.number(o, where, "depth_m", positive=True),
                                    heading_rad=c.number(o, where, "heading_rad"), height_m=h))
        else:
            c.keys(o, where, common + ("x2_m", "y2_m", "thickness_m"))
            x2, y2 = c.number(o, where, "x2_m"), c.number(o, where, "y2_m")
            if x2 == x and y2 == y:
                c.fail(f"{where}.x2_m", "an end point different from (x_m, y_m)", x2)
            th = c.number(o, where, "thickness_m", DEFAULT_WALL_THICKNESS_M, required=False,
                          positive=True)
            out.append(ObstacleSpec(shape, x, y, x2_m=x2, y2_m=y2, thickness_m=th, height_m=h))
    return tuple(out)


def _parse_camera(c: _Checker, cam: dict, method: str) -> CameraSpec:
    keys = ("f_px", "u0_px", "v0_px", "noise_std", "blur_px", "brightness")
    c.keys(cam, "camera", keys)
    d = CAMERA_DEFAULTS[method]
    return CameraSpec(
        f_px=c.number(cam, "camera", "f_px", d["f_px"], required=False, positive=True),
        u0_px=c.number(cam, "camera", "u0_px", d["u0_px"], required=False),
        v0_px=c.number(cam, "camera", "v0_px", d["v0_px"], required=False),
        noise_std=c.number(cam, "camera", "noise_std", 0.0, required=False, nonneg=True),
        blur_px=c.number(cam, "camera", "blur_px", 0.0, required=False, nonneg=True),
        brightness=c.number(cam, "camera", "brightness", 1.0, required=False, positive=True),
    )


def _parse_params(c: _Checker, raw: dict, method: str) -> dict[str, float | int]:
    table = PAPER_PARAMS[method]
    out: dict[str, float | int] = {k: v for k, (_, v) in table.items()}
    for key, value in raw.items():
        name = f"params.{key}"
        if key not in table:
            raise ScenarioError(f"{c.source}: {name}: unknown key; expected a parameter of "
                                f"method {method}: {', '.join(table)}")
        kind = table[key][0]
        if kind is int:
            if isinstance(value, bool) or not isinstance(value, int):
                c.fail(name, "an integer", value)
            out[key] = value
        else:
            out[key] = c.number(raw, "params", key)
    return out
