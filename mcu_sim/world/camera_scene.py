"""What the camera can see: scene dataclasses (target, obstacles, clutter) and their 3D geometry.

The scene follows the scenario contract (docs/markers.md): a target of kind ``"radial-symbol"``
(000), ``"red-cylinder"`` or ``"double-cross"`` (002) at (x_m, y_m, heading_rad), circle and box
obstacles, plus clutter of other shapes and colours for false-positive tests. Where the pieces
stand is written in docs/markers.md:

- ``radial-symbol``: a slender cylinder (radius 20 mm) whose top at 0.10 m carries the white
  card with the radial symbol; the card's +x axis (line through both "+") points along heading.
- ``red-cylinder``: the 002 assembly. The red cylinder stands at (x, y); the double-cross guidance
  board stands 0.15 m behind it (against ``heading_rad``), facing ``heading_rad``, its lower edge
  at 0.16 m (above the 0.12 m cylinder), on a thin post.
- ``double-cross``: the board and post alone, centred at (x, y), facing ``heading_rad``.

A held object is drawn where the gripper holds it: ``Target.z_m`` lifts the object (not the
002 board, which stays on its post where ``Target.board`` says). A camera whose optical centre
is inside the object (the eye-in-hand camera of a gripper holding it, or closing on it) sees
nothing but the object's surface: the frame is that surface's colour (:func:`inside_colour`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from mobigrasp.mcu_sim.world import markers as mk

TARGET_KINDS = ("radial-symbol", "double-cross", "red-cylinder")
OBSTACLE_SHAPES = ("circle", "box")
CLUTTER_SHAPES = ("box", "cylinder", "disc", "square", "stripe")
_N_SIDES = 24
_UP = np.array([0.0, 0.0, 1.0])


def _finite(obj, *names: str) -> None:
    for n in names:
        v = getattr(obj, n)
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise ValueError(f"{type(obj).__name__}.{n} must be a finite number, got {v!r}")


def _rgb_ok(obj, rgb) -> None:
    if len(rgb) != 3 or not all(isinstance(c, int) and 0 <= c <= 255 for c in rgb):
        raise ValueError(f"{type(obj).__name__}.rgb must be three ints in [0, 255], got {rgb!r}")


@dataclass(frozen=True)
class Target:
    """The object to grasp and its marker (kinds in TARGET_KINDS)."""

    kind: str
    x_m: float
    y_m: float
    heading_rad: float = 0.0
    z_m: float = 0.0  # the object's base above the ground (lifted by the gripper)
    board: tuple[float, float, float] | None = None  # (x, y, heading) the 002 board stands
    # relative to, where the cylinder stood when lifted; None: the target's own place

    def __post_init__(self) -> None:
        if self.kind not in TARGET_KINDS:
            raise ValueError(f"Target.kind must be one of {TARGET_KINDS}, got {self.kind!r}")
        _finite(self, "x_m", "y_m", "heading_rad", "z_m")
        if self.board is not None and (len(self.board) != 3 or not all(
                isinstance(v, int | float) and math.isfinite(v) for v in self.board)):
            raise ValueError(f"Target.board must be (x_m, y_m, heading_rad), got {self.board!r}")

    def board_place(self) -> tuple[float, float, float]:
        """(x, y, heading) of the place the board stands relative to."""
        return self.board if self.board is not None else (self.x_m, self.y_m, self.heading_rad)


@dataclass(frozen=True)
class Obstacle:
    """A static obstacle: ``circle`` uses radius_m; ``box`` uses width_m, depth_m, heading_rad."""

    shape: str
    x_m: float
    y_m: float
    radius_m: float = 0.0
    width_m: float = 0.0
    depth_m: float = 0.0
    heading_rad: float = 0.0
    height_m: float = 0.40
    rgb: tuple[int, int, int] = (95, 110, 140)

    def __post_init__(self) -> None:
        if self.shape not in OBSTACLE_SHAPES:
            raise ValueError(f"Obstacle.shape must be one of {OBSTACLE_SHAPES}, got {self.shape!r}")
        _finite(self, "x_m", "y_m", "radius_m", "width_m", "depth_m", "heading_rad", "height_m")
        need = ("radius_m",) if self.shape == "circle" else ("width_m", "depth_m")
        for n in need + ("height_m",):
            if getattr(self, n) <= 0:
                raise ValueError(f"Obstacle.{n} must be > 0 for a {self.shape}, "
                                 f"got {getattr(self, n)!r}")
        _rgb_ok(self, self.rgb)


@dataclass(frozen=True)
class Clutter:
    """A distractor: solid ``box``/``cylinder`` (height_m > 0) or flat ``disc``/``square``/
    ``stripe`` decal on the ground (height ignored); ``size_m`` is its width or diameter."""

    shape: str
    x_m: float
    y_m: float
    size_m: float
    rgb: tuple[int, int, int]
    heading_rad: float = 0.0
    height_m: float = 0.0

    def __post_init__(self) -> None:
        if self.shape not in CLUTTER_SHAPES:
            raise ValueError(f"Clutter.shape must be one of {CLUTTER_SHAPES}, got {self.shape!r}")
        _finite(self, "x_m", "y_m", "size_m", "heading_rad", "height_m")
        if self.size_m <= 0:
            raise ValueError(f"Clutter.size_m must be > 0, got {self.size_m!r}")
        if self.shape in ("box", "cylinder") and self.height_m <= 0:
            raise ValueError(f"Clutter.height_m must be > 0 for a solid {self.shape}")
        _rgb_ok(self, self.rgb)


@dataclass(frozen=True)
class Scene:
    """Everything the camera can see. ``seed`` fixes the ground texture of this scene."""

    target: Target | None = None
    obstacles: tuple[Obstacle, ...] = ()
    clutter: tuple[Clutter, ...] = ()
    seed: int = 0

    def __post_init__(self) -> None:
        if self.target is not None and not isinstance(self.target, Target):
            raise ValueError("Scene.target must be a Target or None")
        for name, cls in (("obstacles", Obstacle), ("clutter", Clutter)):
            items = getattr(self, name)
            if not isinstance(items, tuple) or not all(isinstance(i, cls) for i in items):
                raise ValueError(f"Scene.{name} must be a tuple of {cls.__name__}")
        if not isinstance(self.seed, int) or isinstance(self.seed, bool):
            raise ValueError(f"Scene.seed must be an int, got {self.seed!r}")


@dataclass
class Item:
    """One paintable thing: a reference point for depth sorting, its solid faces (drawn first,
    ``(poly_w (K, 3), outward normal_w, rgb)``) and then its planar textures
    ``(PlanarTexture, origin_w, ex_w, ey_w)``. Call :meth:`pack` before drawing."""

    ref_w: np.ndarray
    faces: list = field(default_factory=list)
    textures: list = field(default_factory=list)
    verts: np.ndarray | None = None
    starts: np.ndarray | None = None
    normals: np.ndarray | None = None
    centres: np.ndarray | None = None
    colours: list | None = None  # shaded face colours, filled by the renderer on first use
    # what pack() stacks, already stacked per run of faces added together:
    # (verts (V, 3), vertex counts, normals (F, 3), centres (F, 3)), in face order
    parts: list = field(default_factory=list)

    def add_face(self, poly: np.ndarray, normal: np.ndarray, rgb) -> None:
        """Add one face (its centre computed as :meth:`pack` always did)."""
        self.faces.append((poly, normal, rgb))
        self.parts.append((poly, [len(poly)], normal[None, :], _centre(poly)[None, :]))

    def pack(self) -> Item:
        """Stack face vertices, normals and centres so a pose is applied in one product."""
        if self.faces:
            if sum(len(part[1]) for part in self.parts) == len(self.faces):
                self.verts = np.concatenate([part[0] for part in self.parts])
                self.starts = np.cumsum([0] + [n for part in self.parts for n in part[1]])
                self.normals = np.concatenate([part[2] for part in self.parts])
                self.centres = np.concatenate([part[3] for part in self.parts])
                return self
            # faces appended directly: stacked face by face
            self.verts = np.concatenate([f[0] for f in self.faces])
            self.starts = np.cumsum([0] + [len(f[0]) for f in self.faces])
            self.normals = np.array([f[1] for f in self.faces])
            self.centres = np.array([_centre(f[0]) for f in self.faces])
        return self


def _centre(poly: np.ndarray) -> np.ndarray:
    """The mean of a face's vertices as ndarray.mean(axis=0) computes it (a sum along axis 0,
    divided by the count), without its per-call wrapper cost: a moving target is packed every
    frame."""
    return np.add.reduce(poly, axis=0) / len(poly)


def _circle_xy(x: float, y: float, r: float, n: int = _N_SIDES) -> np.ndarray:
    a = (np.arange(n) + 0.5) * 2 * np.pi / n
    return np.column_stack([x + r * np.cos(a), y + r * np.sin(a)])


def _rect_xy(x: float, y: float, w: float, d: float, heading: float) -> np.ndarray:
    c, s = math.cos(heading), math.sin(heading)
    loc = np.array([[-w / 2, -d / 2], [w / 2, -d / 2], [w / 2, d / 2], [-w / 2, d / 2]])
    return loc @ np.array([[c, s], [-s, c]]) + [x, y]


def _prism(item: Item, foot_xy: np.ndarray, bands, top_rgb) -> None:
    """Sides (bands of (z0, z1, rgb)) and top of a prism on a CCW convex footprint.

    The side quads of every edge and band are built as one array, in the face order edge by
    edge, band by band: each quad is ``[a, z0], [b, z0], [b, z1], [a, z1]`` for the edge from
    footprint point a to the next, b (copies); its normal ``(dy, -dx, 0) / hypot(dx, dy)``
    with ``(dx, dy) = b - a`` (math.hypot per edge); its centre the four vertices summed in
    index order, divided by 4, which is what np.add.reduce along a face's rows computes. The
    faces are views of it. (A moving target is rebuilt every frame: ~100 faces.)"""
    k, nb = len(foot_xy), len(bands)
    a = np.asarray(foot_xy, dtype=float)
    b = np.concatenate((a[1:], a[:1]))  # b[i] = a[(i + 1) % k]
    d = b - a
    hyp = np.array([math.hypot(dx, dy) for dx, dy in d.tolist()])
    n = np.empty((k, 3))
    n[:, 0], n[:, 1], n[:, 2] = d[:, 1], -d[:, 0], 0.0
    n /= hyp[:, None]
    z0 = np.array([band[0] for band in bands], dtype=float)
    z1 = np.array([band[1] for band in bands], dtype=float)
    quads = np.empty((k, nb, 4, 3))
    for v, (xy, z) in enumerate(((a, z0), (b, z0), (b, z1), (a, z1))):
        quads[:, :, v, :2] = xy[:, None, :]
        quads[:, :, v, 2] = z[None, :]
    centres = (((quads[:, :, 0] + quads[:, :, 1]) + quads[:, :, 2]) + quads[:, :, 3]) / 4
    # (views made by iterating the arrays, not by indexing them one by one)
    item.faces.extend(zip(quads.reshape(k * nb, 4, 3), [ni for ni in n for _ in range(nb)],
                          [band[2] for band in bands] * k, strict=True))
    item.parts.append((quads.reshape(-1, 3), [4] * (k * nb), np.repeat(n, nb, axis=0),
                       centres.reshape(-1, 3)))
    ztop = bands[-1][1]
    top = np.column_stack([foot_xy, np.full(k, ztop)])
    item.add_face(top, _UP, top_rgb)


def _flat(item: Item, foot_xy: np.ndarray, rgb) -> None:
    poly = np.column_stack([foot_xy, np.full(len(foot_xy), 0.0005)])
    item.add_face(poly, _UP, rgb)


def _board_frame(t: Target) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centre, unit right (seen from the front) and unit normal of the 002 guidance board."""
    x, y, h = t.board_place()
    c, s = math.cos(h), math.sin(h)
    back = mk.BOARD_BEHIND_M if t.kind == "red-cylinder" else 0.0
    centre = np.array([x - back * c, y - back * s, mk.BOARD_CENTRE_Z_M])
    return centre, np.array([-s, c, 0.0]), np.array([c, s, 0.0])


def _target_items(t: Target) -> list[Item]:
    items: list[Item] = []
    z = t.z_m
    if t.kind == "radial-symbol":
        it = Item(np.array([t.x_m, t.y_m, z + mk.OBJECT_TOP_Z_M / 2]))
        _prism(it, _circle_xy(t.x_m, t.y_m, mk.OBJECT_BODY_RADIUS_M),
               ((z, z + mk.OBJECT_TOP_Z_M, mk.BODY_RGB),), mk.BODY_RGB)
        c, s = math.cos(t.heading_rad), math.sin(t.heading_rad)
        origin = np.array([t.x_m, t.y_m, z + mk.OBJECT_TOP_Z_M + 0.0005])
        it.textures.append((mk.radial_symbol_texture(), origin,
                                     np.array([c, s, 0.0]), np.array([-s, c, 0.0])))
        items.append(it)
        return items
    if t.kind == "red-cylinder":
        it = Item(np.array([t.x_m, t.y_m, z + mk.RED_CYL_HEIGHT_M / 2]))
        _prism(it, _circle_xy(t.x_m, t.y_m, mk.RED_CYL_RADIUS_M),
               tuple((z0 + z, z1 + z, rgb) for z0, z1, rgb in mk.red_cylinder_bands()),
               mk.RED_RGB)
        items.append(it)
    centre, right, normal = _board_frame(t)
    board = Item(centre.copy())
    post = centre[:2] - 0.02 * normal[:2]
    _prism(board, _rect_xy(post[0], post[1], 0.02, 0.02, t.heading_rad),
           ((0.0, mk.BOARD_BOTTOM_Z_M, (120, 120, 120)),), (120, 120, 120))
    back = centre[:2] - 0.005 * normal[:2]
    half = right[:2] * mk.BOARD_WIDTH_M / 2
    foot = np.array([back - half, back + half, centre[:2] + half, centre[:2] - half])
    if _signed_area(foot) < 0:
        foot = foot[::-1]
    z0, z1 = mk.BOARD_BOTTOM_Z_M, mk.BOARD_BOTTOM_Z_M + mk.BOARD_HEIGHT_M
    _prism(board, foot, ((z0, z1, mk.WHITE_RGB),), mk.WHITE_RGB)
    board.textures.append((mk.double_cross_texture(), centre + 0.0005 * normal, right,
                                    _UP.copy()))
    items.append(board)
    return items


def inside_colour(t: Target | None, c) -> tuple[int, int, int] | None:
    """The colour of the object's surface around a camera whose optical centre ``c`` (world,
    m) is inside the object's solid (the post of ``radial-symbol``, the red cylinder), else
    None. The eye-in-hand camera at the fingertip point (eq. (3) of 000) is inside the object
    it holds: its view is the object's surface, nothing beyond."""
    if t is None or t.kind == "double-cross":
        return None
    radius, height = ((mk.OBJECT_BODY_RADIUS_M, mk.OBJECT_TOP_Z_M) if t.kind == "radial-symbol"
                      else (mk.RED_CYL_RADIUS_M, mk.RED_CYL_HEIGHT_M))
    dz = float(c[2]) - t.z_m
    if not 0.0 <= dz <= height or math.hypot(float(c[0]) - t.x_m, float(c[1]) - t.y_m) > radius:
        return None
    if t.kind == "radial-symbol":
        return mk.BODY_RGB
    return next(rgb for z0, z1, rgb in mk.red_cylinder_bands() if dz <= z1)


def _signed_area(p: np.ndarray) -> float:
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


@lru_cache(maxsize=64)
def solids_of_scene(scene: Scene) -> tuple[Item, ...]:
    """All paintable items of the scene (unsorted, packed, cached per scene: treat as read-only);
    the ground is drawn separately."""
    items: list[Item] = []
    if scene.target is not None:
        items.extend(_target_items(scene.target))
    items = [it.pack() for it in items]
    items.extend(_obstacle_item(o) for o in scene.obstacles)
    items.extend(_clutter_item(c) for c in scene.clutter)
    return tuple(items)


@lru_cache(maxsize=256)
def _obstacle_item(o: Obstacle) -> Item:
    """The packed item of one obstacle (cached: obstacles stay while a moving target makes a
    new scene every frame; treat as read-only)."""
    it = Item(np.array([o.x_m, o.y_m, o.height_m / 2]))
    foot = (_circle_xy(o.x_m, o.y_m, o.radius_m) if o.shape == "circle"
            else _rect_xy(o.x_m, o.y_m, o.width_m, o.depth_m, o.heading_rad))
    _prism(it, foot, ((0.0, o.height_m, o.rgb),), o.rgb)
    return it.pack()


@lru_cache(maxsize=256)
def _clutter_item(c: Clutter) -> Item:
    """The packed item of one piece of clutter (cached like :func:`_obstacle_item`)."""
    s = c.size_m
    if c.shape in ("cylinder", "disc"):
        foot = _circle_xy(c.x_m, c.y_m, s / 2)
    else:
        foot = _rect_xy(c.x_m, c.y_m, s, s / 5 if c.shape == "stripe" else s, c.heading_rad)
    it = Item(np.array([c.x_m, c.y_m, max(c.height_m, 0.0) / 2]))
    if c.shape in ("box", "cylinder"):
        _prism(it, foot, ((0.0, c.height_m, c.rgb),), c.rgb)
    else:
        _flat(it, foot, c.rgb)
    return it.pack()


def target_keypoints_w(t: Target) -> dict[str, np.ndarray]:
    """World positions of the marker features detectors measure (ground truth, simulator only).

    radial-symbol: ``symbol_centre``, ``plus_1``, ``plus_2`` (on the card plane);
    red-cylinder: ``ring_lo``, ``ring_hi``, ``cylinder_centre`` (on the axis) and the board's
    points; double-cross / red-cylinder: ``cross_1``, ``cross_2`` (left, right seen from the
    front), ``board_centre``.
    """
    out: dict[str, np.ndarray] = {}
    if t.kind == "radial-symbol":
        c, s = math.cos(t.heading_rad), math.sin(t.heading_rad)
        z = t.z_m + mk.OBJECT_TOP_Z_M + 0.0005
        out["symbol_centre"] = np.array([t.x_m, t.y_m, z])
        for i, (px, py) in enumerate(mk.plus_centres_m(), start=1):
            out[f"plus_{i}"] = np.array([t.x_m + c * px - s * py, t.y_m + s * px + c * py, z])
        return out
    if t.kind == "red-cylinder":
        half = mk.RING_SPACING_M / 2
        mid = t.z_m + mk.RING_MID_Z_M
        out["ring_lo"] = np.array([t.x_m, t.y_m, mid - half])
        out["ring_hi"] = np.array([t.x_m, t.y_m, mid + half])
        out["cylinder_centre"] = np.array([t.x_m, t.y_m, mid])
    centre, right, normal = _board_frame(t)
    out["board_centre"] = centre
    for i, (bx, by) in enumerate(mk.cross_centres_m(), start=1):
        out[f"cross_{i}"] = centre + 0.0005 * normal + bx * right + by * _UP
    return out
