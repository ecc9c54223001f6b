"""Seeded random scenarios for the acceptance campaign (docs/cosim.md) and ``bench loop``.

Three generators, by version name (``GENERATORS``); a seed gives the same scene in its version
for good, so old figures can be re-run with ``version="v1"`` or ``"v2"``.

``v3`` (the default) adds the conditions users try beyond v2: the target 0.3-0.5 m from the
start (``CLOSE_P`` of the scenes: never wholly in view at first) or 3-4.5 m (``FAR_P``), else
0.5-3 m; obstacles in 000 and 002 scenes too (``OBSTACLES_P``, on the way as in 001), and near
the target (``NEAR_TARGET_P``: 0.55-0.9 m from it, at least 60 degrees off the side it is
approached from, so the last metre of search and approach has an obstacle beside it); the camera's
noise std 0-12, brightness 0.45-1.8, blur 0-3 px; harsh faults (UART bit errors 1e-3, 20 %
camera frame drops, 5 % encoder slip) on ``HARSH_FAULTS_P`` of the scenes and v2's light ones
on ``LIGHT_FAULTS_P``. Every method gets 180 s (a target up to 4.5 m away, issue's acceptance).

``v2`` covers what users try: the camera's noise (std 0-8), brightness 0.6-1.4
and blur 0-1.5 px; 001 obstacles mixing circles, boxes and short walls (0.2-0.45 m) at any
angle; 002 boards at any orientation, the target moved during the approach on half the scenes,
boards without a cylinder (``double-cross``, nothing to grasp) on ``BOARD_ALONE_P`` of them;
light faults (UART bit errors 1e-4, 10 % camera frame drops, 3 % encoder slip) on
``LIGHT_FAULTS_P`` of the scenes (not with ``faults=False``: a campaign adds its own).

``v1``, per method: the target 0.5-3 m from the start at any bearing, a random start
heading; for 001 one to three obstacles between robot and target (centres never within 0.6 m
of either end along the line, so start and grasp stay free; a surface can come within ~0.35 m
of the start); for 002 the target is dragged sideways during the approach (as in 002 Fig. 4)
and the board faces the robot's start.
Scenarios are written as TOML and parsed by the normal loader, so they pass its validation.
"""

from __future__ import annotations

import math
import random
from typing import TYPE_CHECKING

from mobigrasp.mcu_sim.world.scenario import Scenario, loads_scenario

if TYPE_CHECKING:
    from mobigrasp.host.task.method import SceneHints

BOARD_ALONE_P = 0.15
LIGHT_FAULTS_P = 0.25
LIGHT_FAULTS = ("[faults]", "uart_bit_error_rate = 0.0001", "camera_drop_rate = 0.1",
                "encoder_slip = 0.03")


DEFAULT_VERSION = "v3"


def random_scenario_toml(method: str, seed: int, version: str = DEFAULT_VERSION,
                         faults: bool = True) -> str:
    """TOML text of random scenario ``seed`` for ``method`` by generator ``version``."""
    if version not in GENERATORS:
        raise ValueError(f"version must be one of {tuple(GENERATORS)}, got {version!r}")
    return GENERATORS[version](method, seed, faults)


def _start(rng: random.Random) -> tuple[float, float, float, float, float]:
    """(dist, bearing, robot heading, target x, target y): the target 0.5-3 m away at any
    bearing from the robot at the origin, the robot at any heading."""
    dist = rng.uniform(0.5, 3.0)
    bearing = rng.uniform(-math.pi, math.pi)
    heading = rng.uniform(-math.pi, math.pi)
    return dist, bearing, heading, dist * math.cos(bearing), dist * math.sin(bearing)


def _drag_points(rng: random.Random, dist: float, bearing: float, tx: float, ty: float
                 ) -> list[tuple[float, float, float]]:
    """The way points (t_s, x_m, y_m) of a target dragged sideways during the approach.

    Paper 002 drags the target during the approach, not during the grasp: the drag ends while
    the robot (V_avg = 0.15 m/s, after a ~1 s search) still has 40-70 % of the distance to go,
    and a close target moves less, so a hand drag stays below ~0.3 m/s."""
    side = rng.choice((-1.0, 1.0)) * rng.uniform(0.1, 0.4) * min(1.0, dist / 1.5)
    nx, ny = -math.sin(bearing), math.cos(bearing)  # sideways to the line of sight
    t1 = 1.0 + rng.uniform(0.3, 0.6) * dist / 0.15
    t0 = max(0.5, min(rng.uniform(2.0, 5.0), t1 - max(1.0, abs(side) / 0.25)))
    return [(t, tx + k * nx, ty + k * ny) for t, k in ((t0, 0.0), (t1, side))]


def _path_lines(points: list[tuple[float, float, float]]) -> list[str]:
    """The ``[[target.path]]`` tables of way points (t_s, x_m, y_m)."""
    lines: list[str] = []
    for t, x, y in points:
        lines += ["[[target.path]]", f"t_s = {t:.2f}", f"x_m = {x:.4f}", f"y_m = {y:.4f}", ""]
    return lines


def _drag_path(rng: random.Random, dist: float, bearing: float, tx: float, ty: float
               ) -> list[str]:
    """The ``[[target.path]]`` of a target dragged sideways during the approach (_drag_points)."""
    return _path_lines(_drag_points(rng, dist, bearing, tx, ty))


def _scene(method: str) -> SceneHints:
    """The method's scene (its ``scene``, host/task/method.py); ValueError naming the known
    methods. The registry is imported here, not with this module, which the CLI's parsers
    import."""
    from mobigrasp.host.task import method_rules

    return method_rules(method).scene


def _v1(method: str, seed: int, faults: bool = True) -> str:
    """The first generator (its seeds reproduce the figures measured with it)."""
    scene = _scene(method)
    rng = random.Random(f"{method}-{seed}")
    dist, bearing, heading, tx, ty = _start(rng)
    # the guidance board faces the robot's start
    t_heading = (math.atan2(-ty, -tx) if scene.guide_board
                 else rng.uniform(-math.pi, math.pi))
    lines = [
        "[scenario]", f'name = "random-{method}-{seed}"', f'method = "{method}"',
        f"seed = {seed}", f"time_limit_s = {scene.time_limit_s}", "",
        "[robot]", "x_m = 0.0", "y_m = 0.0", f"heading_rad = {heading:.6f}", "",
        "[target]", f'kind = "{scene.target_kind}"', f"x_m = {tx:.4f}", f"y_m = {ty:.4f}",
        f"heading_rad = {t_heading:.6f}", "",
    ]
    if scene.moving_target:
        lines += _drag_path(rng, dist, bearing, tx, ty)
    if scene.obstacles and dist > 1.4:
        for _ in range(rng.randint(1, 3)):
            along = rng.uniform(0.6, dist - 0.6)
            off = rng.uniform(-0.5, 0.5)
            ox = along * math.cos(bearing) - off * math.sin(bearing)
            oy = along * math.sin(bearing) + off * math.cos(bearing)
            if rng.random() < 0.5:
                lines += ["[[obstacles]]", 'shape = "circle"', f"x_m = {ox:.4f}",
                          f"y_m = {oy:.4f}", f"radius_m = {rng.uniform(0.1, 0.25):.3f}", ""]
            else:
                lines += ["[[obstacles]]", 'shape = "box"', f"x_m = {ox:.4f}", f"y_m = {oy:.4f}",
                          f"width_m = {rng.uniform(0.2, 0.5):.3f}",
                          f"depth_m = {rng.uniform(0.2, 0.4):.3f}",
                          f"heading_rad = {rng.uniform(0, math.pi):.4f}", ""]
    return "\n".join(lines) + "\n"


def _head(version: str, method: str, seed: int, limit_s: float, heading: float, kind: str,
          tx: float, ty: float, target_heading: float) -> list[str]:
    """The [scenario], [robot] (at the origin) and [target] tables of a v2/v3 scene."""
    return [
        "[scenario]", f'name = "random-{version}-{method}-{seed}"', f'method = "{method}"',
        f"seed = {seed}", f"time_limit_s = {limit_s}", "",
        "[robot]", "x_m = 0.0", "y_m = 0.0", f"heading_rad = {heading:.6f}", "",
        "[target]", f'kind = "{kind}"', f"x_m = {tx:.4f}", f"y_m = {ty:.4f}",
        f"heading_rad = {target_heading:.6f}", "",
    ]


def _obstacle_v2(rng: random.Random, ox: float, oy: float) -> list[str]:
    shape = rng.choice(("circle", "box", "wall"))
    if shape == "circle":
        return ["[[obstacles]]", 'shape = "circle"', f"x_m = {ox:.4f}", f"y_m = {oy:.4f}",
                f"radius_m = {rng.uniform(0.1, 0.25):.3f}", ""]
    if shape == "box":
        return ["[[obstacles]]", 'shape = "box"', f"x_m = {ox:.4f}", f"y_m = {oy:.4f}",
                f"width_m = {rng.uniform(0.2, 0.5):.3f}", f"depth_m = {rng.uniform(0.2, 0.4):.3f}",
                f"heading_rad = {rng.uniform(0, math.pi):.4f}", ""]
    half, a = rng.uniform(0.1, 0.225), rng.uniform(0, math.pi)
    return ["[[obstacles]]", 'shape = "wall"', f"x_m = {ox - half * math.cos(a):.4f}",
            f"y_m = {oy - half * math.sin(a):.4f}", f"x2_m = {ox + half * math.cos(a):.4f}",
            f"y2_m = {oy + half * math.sin(a):.4f}", "thickness_m = 0.05", ""]


def _v2(method: str, seed: int, faults: bool = True) -> str:
    """The widened generator (module docstring)."""
    scene = _scene(method)
    rng = random.Random(f"v2-{method}-{seed}")
    dist, bearing, heading, tx, ty = _start(rng)
    kind = scene.target_kind
    if scene.guide_board and rng.random() < BOARD_ALONE_P:
        kind = "double-cross"
    lines = _head("v2", method, seed, scene.time_limit_s, heading, kind, tx, ty,
                  rng.uniform(-math.pi, math.pi))
    if scene.moving_target and kind != "double-cross" and rng.random() < 0.5:
        lines += _drag_path(rng, dist, bearing, tx, ty)  # as v1 (and 002 Fig. 4)
    if scene.obstacles and dist > 1.4:
        for _ in range(rng.randint(1, 3)):
            along = rng.uniform(0.6, dist - 0.6)
            off = rng.uniform(-0.5, 0.5)
            lines += _obstacle_v2(rng, along * math.cos(bearing) - off * math.sin(bearing),
                                  along * math.sin(bearing) + off * math.cos(bearing))
    lines += ["[camera]", f"noise_std = {rng.uniform(0.0, 8.0):.2f}",
              f"brightness = {rng.uniform(0.6, 1.4):.3f}", f"blur_px = {rng.uniform(0.0, 1.5):.2f}",
              ""]
    if rng.random() < LIGHT_FAULTS_P and faults:
        lines += [*LIGHT_FAULTS, ""]
    return "\n".join(lines) + "\n"


CLOSE_P = 0.2
FAR_P = 0.3
OBSTACLES_P = 0.5
NEAR_TARGET_P = 0.3
HARSH_FAULTS_P = 0.2
HARSH_FAULTS = ("[faults]", "uart_bit_error_rate = 0.001", "camera_drop_rate = 0.2",
                "encoder_slip = 0.05")
LIMIT_V3_S = 180.0
OBSTACLE_REACH_M = 0.33  # farthest any v2 obstacle's surface lies from its centre
START_FREE_M = 0.35  # no obstacle surface nearer the start or the target than this
POST_TURN_RAD = 0.05  # step of the turn of a cylinder whose board's post is near the start


def _near_target_centre(rng: random.Random, bearing: float, tx: float, ty: float,
                        ) -> tuple[float, float]:
    """A centre 0.55-0.9 m from the target, at least 60 degrees off the direction back to the
    start (the side the target is approached from)."""
    r = rng.uniform(0.55, 0.9)
    off = rng.choice((-1.0, 1.0)) * rng.uniform(math.pi / 3, math.pi)
    a = bearing + math.pi + off  # bearing + pi points from the target back to the start
    return tx + r * math.cos(a), ty + r * math.sin(a)


def _post_clearance_m(heading: float, places: list[tuple[float, float]]) -> float:
    """Least distance from the start (the origin) to the surface of the 002 board's post, which
    stands BOARD_POST_BEHIND_M behind a cylinder at ``heading``, over the cylinder's places (its
    start and the segments of its drag). The world's module is imported here, as in _scene."""
    from mobigrasp.mcu_sim.world.obstacles import BOARD_POST_BEHIND_M, BOARD_POST_SIDE_M

    bx, by = BOARD_POST_BEHIND_M * math.cos(heading), BOARD_POST_BEHIND_M * math.sin(heading)
    posts = [(x - bx, y - by) for x, y in places]
    least = min(math.hypot(x, y) for x, y in posts)
    # the drag: the nearest point of its segment (the second and third place)
    for (x0, y0), (x1, y1) in zip(posts[1:-1], posts[2:], strict=True):
        dx, dy = x1 - x0, y1 - y0
        k = max(0.0, min(1.0, -(x0 * dx + y0 * dy) / max(dx * dx + dy * dy, 1e-12)))
        least = min(least, math.hypot(x0 + k * dx, y0 + k * dy))
    return least - BOARD_POST_SIDE_M / math.sqrt(2)  # the square post's corner


def _post_clear_heading(heading: float, bearing: float, places: list[tuple[float, float]]
                        ) -> float:
    """``heading`` turned, the least needed in steps of POST_TURN_RAD, toward the start (bearing
    + pi: the post then stands straight behind the cylinder), until the post's surface is
    START_FREE_M clear of the start, as obstacles are (an unchanged heading when it already is:
    the scene's random draws and every other scene stay as they were)."""
    if _post_clearance_m(heading, places) > START_FREE_M:
        return heading
    toward = bearing + math.pi
    off = math.remainder(heading - toward, 2 * math.pi)
    while off != 0.0 and _post_clearance_m(toward + off, places) <= START_FREE_M:
        off = math.copysign(max(0.0, abs(off) - POST_TURN_RAD), off)
    return math.remainder(toward + off, 2 * math.pi)


def _v3(method: str, seed: int, faults: bool = True) -> str:
    """The generator of close, far and cluttered scenes under a harsher camera (module
    docstring)."""
    scene = _scene(method)
    rng = random.Random(f"v3-{method}-{seed}")
    band = rng.random()
    lo, hi = (0.3, 0.5) if band < CLOSE_P else (3.0, 4.5) if band < CLOSE_P + FAR_P else (0.5, 3.0)
    dist, bearing, heading = rng.uniform(lo, hi), rng.uniform(-math.pi, math.pi), \
        rng.uniform(-math.pi, math.pi)
    tx, ty = dist * math.cos(bearing), dist * math.sin(bearing)
    kind = scene.target_kind
    if scene.guide_board and rng.random() < BOARD_ALONE_P:
        kind = "double-cross"
    target_heading = rng.uniform(-math.pi, math.pi)
    places = [(tx, ty)]
    path: list[str] = []
    if scene.moving_target and kind != "double-cross" and rng.random() < 0.5:
        points = _drag_points(rng, dist, bearing, tx, ty)
        places += [(x, y) for _, x, y in points]
        path = _path_lines(points)
    if kind == "red-cylinder":  # the board's post stands behind the cylinder
        target_heading = _post_clear_heading(target_heading, bearing, places)
    lines = _head("v3", method, seed, LIMIT_V3_S, heading, kind, tx, ty, target_heading) + path
    centres: list[tuple[float, float]] = []
    if dist > 1.4 and (scene.obstacles or rng.random() < OBSTACLES_P):
        for _ in range(rng.randint(1, 3)):
            along, off = rng.uniform(0.6, dist - 0.6), rng.uniform(-0.5, 0.5)
            centres.append((along * math.cos(bearing) - off * math.sin(bearing),
                            along * math.sin(bearing) + off * math.cos(bearing)))
    if rng.random() < NEAR_TARGET_P:
        centres.append(_near_target_centre(rng, bearing, tx, ty))
    free = START_FREE_M + OBSTACLE_REACH_M
    for ox, oy in centres:
        if math.hypot(ox, oy) > free and math.hypot(ox - tx, oy - ty) > free:
            lines += _obstacle_v2(rng, ox, oy)
    lines += ["[camera]", f"noise_std = {rng.uniform(0.0, 12.0):.2f}",
              f"brightness = {rng.uniform(0.45, 1.8):.3f}",
              f"blur_px = {rng.uniform(0.0, 3.0):.2f}", ""]
    roll = rng.random()
    if faults and roll < HARSH_FAULTS_P:
        lines += [*HARSH_FAULTS, ""]
    elif faults and roll < HARSH_FAULTS_P + LIGHT_FAULTS_P:
        lines += [*LIGHT_FAULTS, ""]
    return "\n".join(lines) + "\n"


GENERATORS = {"v1": _v1, "v2": _v2, "v3": _v3}


def random_scenario(method: str, seed: int, version: str = DEFAULT_VERSION) -> Scenario:
    """Random scenario ``seed`` for ``method``, validated by the scenario loader."""
    from mobigrasp.host.task import REGISTRY

    return loads_scenario(random_scenario_toml(method, seed, version),
                          f"random-{version}-{method}-{seed}", methods=REGISTRY)
