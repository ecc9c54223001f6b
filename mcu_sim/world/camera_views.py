"""Seeded camera views for detector tests and the accuracy harness, with their ground truth.

Each sampler returns a :class:`View`: a scene, a camera pose and intrinsics, and the truth the
detector should report, in the paper's camera axes where that is what the detector returns
(Y along the optical axis, X left, Z up; mm and degrees as floats: this is simulator-side truth,
never given to the host). The pose ranges are the ones where the task uses each detector
(docs/markers.md, "Operating ranges"):

- ``radial_far``: searching / Bezier planning, symbol 0.45-1.0 m ahead (horizontally; up to
  ``max_dist_m``, where the detector degrades beyond 1.0 m, see docs/markers.md), camera
  0.28-0.48 m above the floor (the arm's reach) and the view ray at least 14 degrees below the
  horizontal (flatter, the 8 mm ring is under 1.5 px tall), no roll, the whole symbol anywhere
  in the image;
- ``dual_plus``: approach adjustment, camera 0.20-0.45 m from the symbol centre, the view ray
  50-88 degrees below the horizontal, no roll, both "+" in the image;
- ``spoke``: precise grasp, camera looking straight down (±3 degrees) 0.095-0.175 m above the
  top, one "+" within 30 px of the image centre, the nearest-to-horizontal spoke within
  ±30 degrees of the image x axis;
- ``empty``: clutter and obstacles, no target, poses like the three above.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from mobigrasp.mcu_sim.world import markers as mk
from mobigrasp.mcu_sim.world.camera import Intrinsics, look_rotation, project
from mobigrasp.mcu_sim.world.camera_scene import (
    Clutter,
    Obstacle,
    Scene,
    Target,
    target_keypoints_w,
)

INTR_000 = Intrinsics()
MIN_ELEVATION_RAD = math.radians(14.0)  # radial_far: view ray at least this far below level


@dataclass
class View:
    """One camera view and its truth."""

    scene: Scene
    cam_pos_w: np.ndarray
    R_wc: np.ndarray
    intr: Intrinsics = INTR_000
    truth: dict = field(default_factory=dict)


def _seg_dist(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    t = float(np.clip(np.dot(p - a, ab) / max(float(np.dot(ab, ab)), 1e-12), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def _clutter(rng: np.random.Generator, centre: np.ndarray, avoid_r: float, n: int,
             cam_xy: np.ndarray | None = None) -> tuple[Clutter, ...]:
    """n distractors around centre, none within avoid_r of it and, when cam_xy is given, none
    within 0.2 m of the line of sight (the truth assumes the target is not occluded)."""
    out = []
    while len(out) < n:
        d = rng.uniform(avoid_r, avoid_r + 1.2)
        a = rng.uniform(-math.pi, math.pi)
        pxy = np.array([centre[0] + d * math.cos(a), centre[1] + d * math.sin(a)])
        if cam_xy is not None and _seg_dist(pxy, cam_xy, centre[:2]) < 0.2:
            continue
        shape = ("box", "cylinder", "disc", "square", "stripe")[int(rng.integers(5))]
        rgb = tuple(int(v) for v in rng.integers(0, 256, 3))
        h = float(rng.uniform(0.03, 0.25)) if shape in ("box", "cylinder") else 0.0
        out.append(Clutter(shape, float(pxy[0]), float(pxy[1]), float(rng.uniform(0.03, 0.15)),
                           rgb, float(rng.uniform(-math.pi, math.pi)), h))
    return tuple(out)


def _aim(c: np.ndarray, p: np.ndarray, du: float, dv: float, f: float) -> tuple[float, float]:
    """Yaw and pitch that put world point p at pixel offset (du, dv) from (u0, v0), roll 0."""
    d = p - c
    yaw = math.atan2(d[1], d[0]) + math.atan2(du, f)
    pitch = math.atan2(d[2], math.hypot(d[0], d[1])) + math.atan2(dv, f)
    return yaw, max(-math.pi / 2, min(math.pi / 2, pitch))


def _inside(uv: np.ndarray, intr: Intrinsics, margin: float) -> bool:
    return bool(np.all(np.isfinite(uv)) and uv[:, 0].min() >= margin
                and uv[:, 0].max() <= intr.width - 1 - margin and uv[:, 1].min() >= margin
                and uv[:, 1].max() <= intr.height - 1 - margin)


def _truth_000(c: np.ndarray, R: np.ndarray, p: np.ndarray) -> dict:
    pc = R.T @ (p - c)
    return {"y_oc_mm": 1000 * pc[2], "x_oc_mm": -1000 * pc[0], "z_oc_mm": -1000 * pc[1],
            "bearing_deg": math.degrees(math.atan2(-pc[0], pc[2])),
            "range_mm": 1000 * float(np.linalg.norm(pc))}


def _ring_points(t: Target, r: float, n: int = 16) -> np.ndarray:
    a = np.arange(n) * 2 * math.pi / n
    return np.column_stack([t.x_m + r * np.cos(a), t.y_m + r * np.sin(a),
                            np.full(n, mk.OBJECT_TOP_Z_M)])


def radial_far(rng: np.random.Generator, clutter: int = 4, max_dist_m: float = 1.0) -> View:
    """Symbol far ahead (search); truth: symbol centre in paper camera axes."""
    while True:
        t = Target("radial-symbol", float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)),
                   float(rng.uniform(-math.pi, math.pi)))
        dist, hc = rng.uniform(0.45, max_dist_m), rng.uniform(0.28, 0.48)
        beta = rng.uniform(-3.1, 3.1)
        if math.atan2(hc - mk.OBJECT_TOP_Z_M, dist) < MIN_ELEVATION_RAD:
            continue
        c = np.array([t.x_m - dist * math.cos(beta), t.y_m - dist * math.sin(beta), hc])
        centre = target_keypoints_w(t)["symbol_centre"]
        yaw, pitch = _aim(c, centre, rng.uniform(-140, 140), rng.uniform(-100, 100),
                          INTR_000.f_px)
        R = look_rotation(yaw, pitch)
        if _inside(project(_ring_points(t, mk.CARD_RADIUS_M), c, R, INTR_000), INTR_000, 3):
            break
    scene = Scene(t, clutter=_clutter(rng, centre, 0.25, clutter, c[:2]),
                  seed=int(rng.integers(1 << 16)))
    return View(scene, c, R, INTR_000, _truth_000(c, R, centre))


def radial_ahead(dist_m: float, heading_rad: float, beta_rad: float, hc_m: float = 0.30,
                 du_px: float = 0.0, dv_px: float = 0.0, seed: int = 3) -> View:
    """Symbol ``dist_m`` ahead (horizontal) of the search camera ``hc_m`` up, seen from
    direction ``beta_rad`` with its centre (du_px, dv_px) off the image centre, no clutter (a
    fixed pose: how far the symbol is read, docs/markers.md "Camera gain"); truth as
    :func:`radial_far`."""
    t = Target("radial-symbol", 0.0, 0.0, heading_rad)
    c = np.array([-dist_m * math.cos(beta_rad), -dist_m * math.sin(beta_rad), hc_m])
    centre = target_keypoints_w(t)["symbol_centre"]
    yaw, pitch = _aim(c, centre, du_px, dv_px, INTR_000.f_px)
    R = look_rotation(yaw, pitch)
    return View(Scene(t, seed=seed), c, R, INTR_000, _truth_000(c, R, centre))


def radial_cut(rng: np.random.Generator, du_px: float) -> View:
    """Symbol near the camera (0.3-0.45 m, the camera 0.28-0.34 m up, a close start) with its
    centre ``du_px`` from the image centre: cut by the border for |du_px| > 160; truth: the
    camera's distance to the symbol's centre."""
    t = Target("radial-symbol", 0.0, 0.0, float(rng.uniform(-math.pi, math.pi)))
    dist, hc, beta = rng.uniform(0.3, 0.45), rng.uniform(0.28, 0.34), rng.uniform(-3.1, 3.1)
    c = np.array([-dist * math.cos(beta), -dist * math.sin(beta), hc])
    centre = target_keypoints_w(t)["symbol_centre"]
    yaw, pitch = _aim(c, centre, du_px, rng.uniform(-30, 30), INTR_000.f_px)
    return View(Scene(t, seed=int(rng.integers(1 << 16))), c, look_rotation(yaw, pitch),
                INTR_000, {"dist_m": float(np.linalg.norm(centre - c))})


def dual_plus(rng: np.random.Generator, clutter: int = 4) -> View:
    """Camera above and beside the object (approach adjustment); truth also has the "+" pixels."""
    while True:
        t = Target("radial-symbol", float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)),
                   float(rng.uniform(-math.pi, math.pi)))
        kp = target_keypoints_w(t)
        dist, el, beta = rng.uniform(0.20, 0.45), rng.uniform(0.87, 1.54), rng.uniform(-3.1, 3.1)
        centre = kp["symbol_centre"]
        c = centre + dist * np.array([-math.cos(el) * math.cos(beta),
                                      -math.cos(el) * math.sin(beta), math.sin(el)])
        yaw, pitch = _aim(c, centre, rng.uniform(-120, 120), rng.uniform(-90, 90), INTR_000.f_px)
        R = look_rotation(yaw, pitch)
        half = mk.PLUS_HALF_SPAN_M * 1.5
        pts = [kp[n] + np.array([dx, dy, 0.0]) for n in ("plus_1", "plus_2")
               for dx, dy in ((half, 0), (-half, 0), (0, half), (0, -half))]
        if _inside(project(np.array(pts), c, R, INTR_000), INTR_000, 2):
            break
    scene = Scene(t, clutter=_clutter(rng, centre, 0.25, clutter, c[:2]),
                  seed=int(rng.integers(1 << 16)))
    truth = _truth_000(c, R, centre)
    truth["plus_uv"] = project(np.array([kp["plus_1"], kp["plus_2"]]), c, R, INTR_000)
    truth["alpha_rad"] = pitch
    return View(scene, c, R, INTR_000, truth)


def spoke(rng: np.random.Generator) -> View:
    """Camera straight down over one "+"; truth: spoke angle (deg, image, v down) and width."""
    t = Target("radial-symbol", float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)),
               float(rng.uniform(-math.pi, math.pi)))
    kp = target_keypoints_w(t)
    plus = kp["plus_1"] if rng.integers(2) == 0 else kp["plus_2"]
    height = rng.uniform(0.095, 0.175)
    spoke_deg = rng.uniform(-30.0, 30.0)
    # looking down with yaw psi, image x is world (sin psi, -cos psi): choose psi so that the
    # card's x axis (one spoke direction) appears at spoke_deg from image x
    psi = t.heading_rad + math.pi / 2 + math.radians(spoke_deg) + rng.integers(4) * math.pi / 2
    off = rng.uniform(-30, 30, 2) * height / INTR_000.f_px
    c = plus + np.array([off[0], off[1], height])
    R = look_rotation(psi, -math.pi / 2 + rng.uniform(-0.05, 0.05))
    ch, sh = math.cos(t.heading_rad), math.sin(t.heading_rad)
    arms = np.array([plus + s * mk.PLUS_HALF_SPAN_M * np.array(v) for v in
                     ((ch, sh, 0.0), (-sh, ch, 0.0)) for s in (1, -1)])
    uv = project(np.vstack([plus[None], arms]), c, R, INTR_000)
    angles = []
    for a, b in ((1, 2), (3, 4)):
        d = uv[a] - uv[b]
        ang = math.degrees(math.atan2(d[1], d[0]))
        angles.append((ang + 90.0) % 180.0 - 90.0)
    ang = min(angles, key=abs)
    depth = float((R.T @ (plus - c))[2])
    truth = {"centre_uv": uv[0], "angle_deg": ang,
             "width_px": mk.PLUS_ARM_WIDTH_M * INTR_000.f_px / depth, "height_m": depth}
    return View(Scene(t, seed=int(rng.integers(1 << 16))), c, R, INTR_000, truth)


def empty(rng: np.random.Generator, clutter: int = 10) -> View:
    """No target: clutter of other shapes and colours and an obstacle, seen like the above."""
    centre = np.array([rng.uniform(-1, 1), rng.uniform(-1, 1), 0.0])
    items = _clutter(rng, centre, 0.0, clutter)
    obs = (Obstacle("circle", float(centre[0] + rng.uniform(-0.8, 0.8)),
                    float(centre[1] + rng.uniform(-0.8, 0.8)), radius_m=0.1,
                    rgb=tuple(int(v) for v in rng.integers(0, 256, 3))),)
    dist, hc, beta = rng.uniform(0.2, 1.2), rng.uniform(0.15, 0.45), rng.uniform(-3.1, 3.1)
    c = np.array([centre[0] - dist * math.cos(beta), centre[1] - dist * math.sin(beta), hc])
    yaw, pitch = _aim(c, centre, rng.uniform(-100, 100), rng.uniform(-80, 80), INTR_000.f_px)
    R = look_rotation(yaw, pitch)
    return View(Scene(None, obs, items, seed=int(rng.integers(1 << 16))), c, R, INTR_000, {})
