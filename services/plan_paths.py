"""The planned paths a trace's ``plan`` details name, as world-frame poly-lines (plots, MCAP).

A plan entry holds sampled paths or the control points of cubic Beziers (``candidates_ctrl``,
``best_ctrl``, or ``candidates``/``best``), in mm or m, in the host's odometry frame (its start
pose); :func:`plan_paths_world` returns both lists in world metres.
"""

from __future__ import annotations

import math
from collections.abc import Callable

Point = tuple[float, float]


def cubic_points(ctrl: list, n: int = 40) -> list[tuple[float, float]]:
    """Points of the cubic Bezier with control points ``ctrl`` ([x, y(, t)] each), eq. (4) of
    000 with the Bernstein basis."""
    (x0, y0), (x1, y1), (x2, y2), (x3, y3) = [(p[0], p[1]) for p in ctrl[:4]]
    out = []
    for i in range(n + 1):
        t = i / n
        b0, b1, b2, b3 = (1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t * t * (1 - t), t ** 3
        out.append((b0 * x0 + b1 * x1 + b2 * x2 + b3 * x3, b0 * y0 + b1 * y1 + b2 * y2 + b3 * y3))
    return out


def _curves(plan: dict, key: str) -> list[list[tuple[float, float]]]:
    """Poly-lines of a plan entry: sampled paths, or control points of cubic Beziers."""
    value = plan.get(key)
    if not isinstance(value, list) or not value:
        return []
    if all(isinstance(p, list) and len(p) >= 2 and isinstance(p[0], int | float) for p in value):
        return [cubic_points(value)] if len(value) == 4 else [[(p[0], p[1]) for p in value]]
    out = []
    for item in value:
        out.extend(_curves({"c": item}, "c"))
    return out


def odom_to_world(start: dict | None):
    """The host plans in its odometry frame (the start pose); map to the world for plotting."""
    x0, y0, h0 = (start or {}).get("robot", [0.0, 0.0, 0.0])
    c, s = math.cos(h0), math.sin(h0)
    return lambda p: (x0 + c * p[0] - s * p[1], y0 + s * p[0] + c * p[1])


def plan_paths_world(plan: dict, to_world: Callable[[Point], Point]
                     ) -> tuple[list[list[Point]], list[list[Point]]]:
    """(candidates, chosen) poly-lines of one plan entry, in world metres."""
    cands = _curves(plan, "candidates_ctrl") or _curves(plan, "candidates")
    best = _curves(plan, "best_ctrl") or _curves(plan, "best")
    pts = [p for path in cands + best for p in path]
    scale = 1e-3 if pts and max(abs(v) for p in pts for v in p) > 50 else 1.0  # mm or m
    return ([[to_world((p[0] * scale, p[1] * scale)) for p in path] for path in cands],
            [[to_world((p[0] * scale, p[1] * scale)) for p in path] for path in best])
