"""Scenario files: TOML (tomllib) loading and strict validation into frozen dataclasses.

Contract: ``[scenario]`` name, method (a name of the method table the loader is given),
seed, time_limit_s;
``[robot]`` x_m, y_m, heading_rad; ``[target]`` kind, x_m, y_m, heading_rad and optional
``[[target.path]]`` t_s, x_m, y_m; ``[[obstacles]]`` shape "circle" (radius_m) or "box"
(width_m, depth_m, heading_rad), or "wall" (x2_m, y2_m, optional thickness_m), each with an
optional height_m; ``[camera]`` optional f_px, u0_px, v0_px, noise_std, blur_px, brightness;
``[params]`` overrides of the method's paper parameters (names, defaults and ranges in the
method's ``paper_params``); ``[faults]`` the injected faults, validated into a
:class:`mobigrasp.mcu_sim.faults.plan.FaultPlan` (keys in docs/faults.md).

Every value is checked against the physical range written beside it below (and listed in
docs/conventions.md "Scenario value ranges"), and the geometry is checked: no obstacle on the
robot's start footprint, the target (and its path) clear of obstacles and of the robot. Every
problem raises :class:`ScenarioError` naming the file, the key and what was expected.

The methods are the host's (host/task/method.py): each loader function receives their table
(``methods``, name -> :class:`MethodSchema`; the callers pass ``host.task.REGISTRY``), so that
this module, read by the simulator, imports nothing of the host (pyproject's import contracts)
and a method added to the host's registry is one the loader accepts.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Protocol

from mobigrasp.mcu_sim import checks
from mobigrasp.mcu_sim.faults.plan import FaultError, FaultPlan, parse_faults

TARGET_KINDS = ("radial-symbol", "double-cross", "red-cylinder")
OBSTACLE_SHAPES = ("circle", "box", "wall")
DEFAULT_OBSTACLE_HEIGHT_M = 0.30
DEFAULT_WALL_THICKNESS_M = 0.05

# The physical range of every value (docs/conventions.md "Scenario value ranges" lists them).
# The floor is a 100 m x 100 m hall around the origin; an angle is within one turn either way.
WORLD_HALF_M = 50.0
ANGLE_MAX_RAD = 2 * math.pi
_XY = (-WORLD_HALF_M, WORLD_HALF_M)
_ANGLE = (-ANGLE_MAX_RAD, ANGLE_MAX_RAD)
# The longest run: host state is bounded (docs/cosim.md "Long runs"), the trace grows with it.
MAX_TIME_LIMIT_S = 3600.0
MAX_SEED = 2**64 - 1  # seeds are 64-bit (numpy's and the campaign's generators)
MAX_NAME_CHARS = 200
MAX_OBSTACLES = 200
MAX_PATH_POINTS = 1000
# a target dragged by hand (002 Fig. 4) moves at walking pace at most
MAX_TARGET_SPEED_MPS = 2.0
# obstacles: radius, box sides, wall thickness, height (m)
OBSTACLE_RANGES = {"radius_m": (0.005, 10.0), "width_m": (0.005, 20.0),
                   "depth_m": (0.005, 20.0), "thickness_m": (0.005, 2.0),
                   "height_m": (0.01, 3.0)}
# camera: intrinsics within the 320 x 240 image (the principal point on the sensor), the
# degradations within what mcu_sim/world/camera.py CameraOptions renders
CAMERA_RANGES = {"f_px": (50.0, 5000.0), "u0_px": (0.0, 320.0), "v0_px": (0.0, 240.0),
                 "noise_std": (0.0, 128.0), "blur_px": (0.0, 40.0), "brightness": (0.01, 10.0)}


class ParamSchema(Protocol):
    """A paper parameter as the loader reads it: type (int: must be an integer; float accepts
    int or float), the paper's value, the physical range [lo, hi] and its unit/meaning."""

    kind: type
    default: float
    lo: float
    hi: float
    unit: str


class CameraIntrinsics(Protocol):
    """A method's camera: the ``[camera]`` defaults (px)."""

    f_px: float
    u0_px: float
    v0_px: float


class MethodSchema(Protocol):
    """What the loader reads of a method (the host's method objects, host/task/method.py,
    are these; the loader receives their table, as mcu_sim never imports the host)."""

    paper_params: Mapping[str, ParamSchema]
    not_used_params: tuple[str, ...]
    param_order: tuple[tuple[str, str, float], ...]
    camera: CameraIntrinsics
    robot: str  # the robot the world builds (mcu_sim/world/arm.py ARM_BY_METHOD)


class ScenarioError(checks.BadValue):
    """A scenario file is malformed: the message names the file, the key and what was expected."""


@dataclass(frozen=True)
class ScenarioMeta:
    """``[scenario]``."""

    name: str
    method: str
    seed: int
    time_limit_s: float
    robot: str  # the robot the world builds: the method's (its ``robot``)


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


def load_scenario(path: str | Path, *, methods: Mapping[str, MethodSchema]) -> Scenario:
    """Read and validate a scenario file."""
    p = Path(path)
    return loads_scenario(checks.read_text(p, "scenario file", ScenarioError), str(p),
                          methods=methods)


def loads_scenario(text: str, source: str = "<string>", *,
                   methods: Mapping[str, MethodSchema]) -> Scenario:
    """Parse and validate scenario TOML text; ``source`` names it in error messages."""
    return parse_scenario(checks.load_toml(text, source, ScenarioError), source, methods=methods)


class _Checker:
    """Typed field access with errors naming file, key and expectation."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, key: str, expected: str, got: Any = None, present: bool = True) -> None:
        checks.fail(self.source, key, expected, got if present else checks.MISSING,
                    ScenarioError)

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
                name = checks.key_text(f"{where}.{k}" if where else k)
                raise ScenarioError(f"{self.source}: {name}: unknown key; expected one of: "
                                    f"{', '.join(allowed)}")

    def number(self, table: dict, where: str, key: str, rng: tuple[float, float],
               default: float | None = None, required: bool = True, unit: str = "") -> Any:
        """A finite number in the closed range ``rng`` (unit named in the message)."""
        name = f"{where}.{key}"
        if key not in table:
            if required:
                self.fail(name, "a number (missing)", present=False)
            return default
        return checks.number(table[key], self.source, name, rng[0], rng[1], unit, ScenarioError)

    def integer(self, table: dict, where: str, key: str, rng: tuple[int, int],
                unit: str = "") -> int:
        name = f"{where}.{key}"
        if key not in table:
            self.fail(name, "an integer (missing)", present=False)
        return checks.integer(table[key], self.source, name, rng[0], rng[1], unit, ScenarioError)

    def choice(self, table: dict, where: str, key: str, options: tuple[str, ...]) -> str:
        name = f"{where}.{key}"
        expected = "one of " + ", ".join(f'"{o}"' for o in options)
        if key not in table:
            self.fail(name, f"{expected} (missing)", present=False)
        v = table[key]
        if not isinstance(v, str) or v not in options:
            self.fail(name, expected, v)
        return v


def parse_scenario(data: dict, source: str = "<dict>", *,
                   methods: Mapping[str, MethodSchema]) -> Scenario:
    """Validate an already-parsed TOML document."""
    c = _Checker(source)
    c.keys(data, "", ("scenario", "robot", "target", "obstacles", "camera", "params", "faults"))

    s = c.table(data, "scenario")
    c.keys(s, "scenario", ("name", "method", "seed", "time_limit_s"))
    name = s.get("name")
    if not isinstance(name, str) or not 0 < len(name) <= MAX_NAME_CHARS:
        c.fail("scenario.name", f"a non-empty string of at most {MAX_NAME_CHARS} characters",
               name, present="name" in s)
    method = c.choice(s, "scenario", "method", tuple(methods))
    schema = methods[method]
    seed = c.integer(s, "scenario", "seed", (0, MAX_SEED))
    meta = ScenarioMeta(name, method, seed,
                        c.number(s, "scenario", "time_limit_s", (0.001, MAX_TIME_LIMIT_S),
                                 unit="s"), schema.robot)

    r = c.table(data, "robot")
    c.keys(r, "robot", ("x_m", "y_m", "heading_rad"))
    robot = RobotStart(c.number(r, "robot", "x_m", _XY, unit="m"),
                       c.number(r, "robot", "y_m", _XY, unit="m"),
                       c.number(r, "robot", "heading_rad", _ANGLE, unit="rad"))

    target = _parse_target(c, c.table(data, "target"))
    obstacles = _parse_obstacles(c, data.get("obstacles", []))
    camera = _parse_camera(c, c.table(data, "camera", required=False) or {}, schema.camera)
    raw_params = c.table(data, "params", required=False) or {}
    params = _parse_params(c, raw_params, method, schema)
    faults_table = c.table(data, "faults", required=False) or {}
    try:
        faults = parse_faults(faults_table, source)
    except FaultError as exc:
        raise ScenarioError(str(exc)) from exc
    overrides = {k: params[k] for k in raw_params}
    _check_geometry(c, robot, target, obstacles)
    return Scenario(source, meta, robot, target, obstacles, camera,
                    MappingProxyType(params), faults,
                    MappingProxyType(overrides))


def _parse_target(c: _Checker, t: dict) -> TargetSpec:
    c.keys(t, "target", ("kind", "x_m", "y_m", "heading_rad", "path"))
    kind = c.choice(t, "target", "kind", TARGET_KINDS)
    x, y = c.number(t, "target", "x_m", _XY, unit="m"), c.number(t, "target", "y_m", _XY, unit="m")
    heading = c.number(t, "target", "heading_rad", _ANGLE, unit="rad")
    raw_path = t.get("path", [])
    if not isinstance(raw_path, list):
        c.fail("target.path", "an array of tables [[target.path]]", raw_path)
    if len(raw_path) > MAX_PATH_POINTS:
        c.fail("target.path", f"at most {MAX_PATH_POINTS} way points", len(raw_path))
    path: list[PathPoint] = []
    prev = PathPoint(0.0, x, y)  # where the target stands at the start
    for i, entry in enumerate(raw_path):
        where = f"target.path[{i}]"
        if not isinstance(entry, dict):
            c.fail(where, "a table with t_s, x_m, y_m", entry)
        c.keys(entry, where, ("t_s", "x_m", "y_m"))
        pt = PathPoint(c.number(entry, where, "t_s", (0.0, MAX_TIME_LIMIT_S), unit="s"),
                       c.number(entry, where, "x_m", _XY, unit="m"),
                       c.number(entry, where, "y_m", _XY, unit="m"))
        if path and pt.t_s <= path[-1].t_s:
            c.fail(f"{where}.t_s", f"a time later than {path[-1].t_s} s (strictly increasing)",
                   pt.t_s)
        step_m = math.hypot(pt.x_m - prev.x_m, pt.y_m - prev.y_m)
        if step_m > MAX_TARGET_SPEED_MPS * (pt.t_s - prev.t_s):
            c.fail(where, f"a way point the target reaches at <= {MAX_TARGET_SPEED_MPS:g} m/s "
                          f"from the one before ({step_m:.3f} m in {pt.t_s - prev.t_s:g} s)",
                   (pt.t_s, pt.x_m, pt.y_m))
        path.append(pt)
        prev = pt
    return TargetSpec(kind, x, y, heading, tuple(path))


def _obstacle_size(c: _Checker, o: dict, where: str, key: str,
                   default: float | None = None) -> float:
    return c.number(o, where, key, OBSTACLE_RANGES[key], default, required=default is None,
                    unit="m")


def _parse_obstacles(c: _Checker, raw: Any) -> tuple[ObstacleSpec, ...]:
    if not isinstance(raw, list):
        c.fail("obstacles", "an array of tables [[obstacles]]", raw)
    if len(raw) > MAX_OBSTACLES:
        c.fail("obstacles", f"at most {MAX_OBSTACLES} obstacles", len(raw))
    out = []
    for i, o in enumerate(raw):
        where = f"obstacles[{i}]"
        if not isinstance(o, dict):
            c.fail(where, "a table", o)
        shape = c.choice(o, where, "shape", OBSTACLE_SHAPES)
        common = ("shape", "x_m", "y_m", "height_m")
        x, y = c.number(o, where, "x_m", _XY, unit="m"), c.number(o, where, "y_m", _XY, unit="m")
        h = _obstacle_size(c, o, where, "height_m", DEFAULT_OBSTACLE_HEIGHT_M)
        if shape == "circle":
            c.keys(o, where, common + ("radius_m",))
            out.append(ObstacleSpec(shape, x, y, radius_m=_obstacle_size(c, o, where, "radius_m"),
                                    height_m=h))
        elif shape == "box":
            c.keys(o, where, common + ("width_m", "depth_m", "heading_rad"))
            out.append(ObstacleSpec(shape, x, y,
                                    width_m=_obstacle_size(c, o, where, "width_m"),
                                    depth_m=_obstacle_size(c, o, where, "depth_m"),
                                    heading_rad=c.number(o, where, "heading_rad", _ANGLE,
                                                         unit="rad"),
                                    height_m=h))
        else:
            c.keys(o, where, common + ("x2_m", "y2_m", "thickness_m"))
            x2 = c.number(o, where, "x2_m", _XY, unit="m")
            y2 = c.number(o, where, "y2_m", _XY, unit="m")
            if math.hypot(x2 - x, y2 - y) < 0.01:
                c.fail(f"{where}.x2_m", "an end point at least 0.01 m from (x_m, y_m)", x2)
            th = _obstacle_size(c, o, where, "thickness_m", DEFAULT_WALL_THICKNESS_M)
            out.append(ObstacleSpec(shape, x, y, x2_m=x2, y2_m=y2, thickness_m=th, height_m=h))
    return tuple(out)


def _parse_camera(c: _Checker, cam: dict, intrinsics: CameraIntrinsics) -> CameraSpec:
    c.keys(cam, "camera", tuple(CAMERA_RANGES))
    d = {"noise_std": 0.0, "blur_px": 0.0, "brightness": 1.0, "f_px": float(intrinsics.f_px),
         "u0_px": float(intrinsics.u0_px), "v0_px": float(intrinsics.v0_px)}
    return CameraSpec(**{k: c.number(cam, "camera", k, rng, d[k], required=False)
                         for k, rng in CAMERA_RANGES.items()})


def _parse_params(c: _Checker, raw: dict, method: str,
                  schema: MethodSchema, unused_ok: bool = False) -> dict[str, float | int]:
    table = schema.paper_params
    out: dict[str, float | int] = {k: p.default for k, p in table.items()}
    for key in raw:
        if key not in table:
            raise ScenarioError(f"{c.source}: {checks.key_text(f'params.{key}')}: unknown key; "
                                f"expected a parameter of method {method}: {', '.join(table)}")
        if key in schema.not_used_params and not unused_ok:
            raise ScenarioError(f"{c.source}: params.{key}: {key} is not used by method "
                                f"{method}")
        p = table[key]
        if p.kind is int:
            out[key] = c.integer(raw, "params", key, (int(p.lo), int(p.hi)), p.unit)
        else:
            out[key] = c.number(raw, "params", key, (p.lo, p.hi), unit=p.unit)
    checks.ordered(out, schema.param_order, c.source, "params.", ScenarioError, given=raw)
    return out


# --- the host program's configuration (``mobigrasp host --config``) ---------------------------

HOST_CONFIG_KEYS = ("method", "params", "camera", "task")
HOST_TASK_KEYS = ("timeouts_us", "object_xy_mm")
_STATE_NAME_CHARS = 20


def parse_host_config(cfg: Any, source: str, *,
                      methods: Mapping[str, MethodSchema]) -> dict:
    """A host configuration (what ``mobigrasp run`` gives its host process: method, paper
    parameters, camera intrinsics, task settings) checked as a scenario's values are: the same
    ranges and ordered pairs, the principal point within the image. ScenarioError naming
    ``source`` and the key otherwise. Keys not given stay out (the host's defaults)."""
    c = _Checker(source)
    checks.nested(cfg, source, "(document)", ScenarioError)
    if not isinstance(cfg, dict):
        c.fail("(document)", "a JSON object with " + ", ".join(HOST_CONFIG_KEYS), cfg)
    c.keys(cfg, "", HOST_CONFIG_KEYS)
    method = cfg.get("method", next(iter(methods)))
    if not isinstance(method, str) or method not in methods:
        c.fail("method", "one of " + ", ".join(f'"{m}"' for m in methods), method)
    schema = methods[method]
    out: dict[str, Any] = {"method": method}
    if "params" in cfg:
        raw = c.table(cfg, "params")
        full = _parse_params(c, raw, method, schema, unused_ok=True)
        out["params"] = {k: full[k] for k in raw}
    if "camera" in cfg:
        cam = c.table(cfg, "camera")
        full_cam = _parse_camera(c, cam, schema.camera)
        out["camera"] = {k: getattr(full_cam, k) for k in cam}
    if "task" in cfg:
        task = c.table(cfg, "task")
        c.keys(task, "task", HOST_TASK_KEYS)
        out["task"] = {}
        if "timeouts_us" in task:
            tmo = task["timeouts_us"]
            if not isinstance(tmo, dict):
                c.fail("task.timeouts_us", "a table of task states and µs", tmo)
            for state in tmo:
                if not state.isupper() or len(state) > _STATE_NAME_CHARS:
                    c.fail(f"task.timeouts_us.{checks.key_text(state)}",
                           "a task state's name (SEARCH, APPROACH, ...)", state)
                c.integer(tmo, "task.timeouts_us", state, (1, int(MAX_TIME_LIMIT_S * 1e6)), "us")
            out["task"]["timeouts_us"] = dict(tmo)
        if "object_xy_mm" in task:
            xy = task["object_xy_mm"]
            if not isinstance(xy, list) or len(xy) not in (0, 2):
                c.fail("task.object_xy_mm", "[x, y] in mm, or []", xy)
            lim = int(WORLD_HALF_M * 2000)
            for k, v in enumerate(xy):
                checks.integer(v, source, f"task.object_xy_mm[{k}]", -lim, lim, "mm",
                               ScenarioError)
            out["task"]["object_xy_mm"] = list(xy)
    return out


# --- geometry: the robot's start and the target stand free ----------------------------------

# footprints (m): mcu_sim/world/base.py FOOTPRINT_RADIUS_M and obstacles.py TARGET_GEOMETRY
ROBOT_FOOTPRINT_M = 0.17
TARGET_FOOTPRINT_M = {"radial-symbol": 0.020, "double-cross": 0.020, "red-cylinder": 0.025}


def obstacle_clearance_m(o: ObstacleSpec, x: float, y: float) -> float:
    """Distance from (x, y) to the obstacle's surface on the floor (negative inside)."""
    if o.shape == "circle":
        return math.hypot(x - o.x_m, y - o.y_m) - o.radius_m
    if o.shape == "box":  # in the box's frame: width along its heading, depth across
        c, s = math.cos(o.heading_rad), math.sin(o.heading_rad)
        dx, dy = x - o.x_m, y - o.y_m
        u, v = abs(c * dx + s * dy) - o.width_m / 2, abs(-s * dx + c * dy) - o.depth_m / 2
        if u <= 0 and v <= 0:
            return max(u, v)
        return math.hypot(max(u, 0.0), max(v, 0.0))
    ax, ay, bx, by = o.x_m, o.y_m, o.x2_m, o.y2_m  # wall: a segment thickness_m wide
    ex, ey = bx - ax, by - ay
    k = max(0.0, min(1.0, ((x - ax) * ex + (y - ay) * ey) / (ex * ex + ey * ey)))
    return math.hypot(x - ax - k * ex, y - ay - k * ey) - o.thickness_m / 2


def _check_geometry(c: _Checker, robot: RobotStart, target: TargetSpec,
                    obstacles: tuple[ObstacleSpec, ...]) -> None:
    """Nothing overlaps the robot's start footprint; the target (and every way point of its
    path) stands free of the obstacles, and it does not start on the robot."""
    r_t = TARGET_FOOTPRINT_M[target.kind]
    for i, o in enumerate(obstacles):
        gap = obstacle_clearance_m(o, robot.x_m, robot.y_m) - ROBOT_FOOTPRINT_M
        if gap <= 0:
            c.fail(f"obstacles[{i}]", f"an obstacle clear of the robot's start footprint "
                                      f"({ROBOT_FOOTPRINT_M} m around robot.x_m, robot.y_m; "
                                      f"overlap {-gap:.3f} m)", o.shape)
        for j, (x, y) in enumerate([(target.x_m, target.y_m)]
                                   + [(p.x_m, p.y_m) for p in target.path]):
            gap = obstacle_clearance_m(o, x, y) - r_t
            if gap <= 0:
                key = "target" if j == 0 else f"target.path[{j - 1}]"
                c.fail(key, f"a target position clear of obstacles[{i}] (overlap "
                            f"{-gap:.3f} m)", (x, y))
    gap = math.hypot(target.x_m - robot.x_m, target.y_m - robot.y_m) - ROBOT_FOOTPRINT_M - r_t
    if gap <= 0:
        c.fail("target", f"a target clear of the robot's start footprint (overlap "
                         f"{-gap:.3f} m)", (target.x_m, target.y_m))


def run_time_limit_s(scenario: Scenario, asked_s: float | None) -> float:
    """A run's time limit: the one asked for (``--time-limit-s``), else the scenario's."""
    return asked_s or scenario.meta.time_limit_s
