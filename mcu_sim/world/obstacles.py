"""Static obstacles, the graspable target object and contact counting in the pymunk space.

Obstacles (circles, boxes with a heading, walls as thick segments) live on the space's static
body. The target is a dynamic body that the base can push; ground friction is emulated as in
pymunk's examples/tank.py (PivotJoint + GearJoint to the static body with ``max_bias = 0`` and
``max_force`` = mu * m * g). A target with a ``[[target.path]]`` is kinematic instead and is
dragged along the path by velocity (paper 002 moves the object by hand during the approach).

Contacts are counted as episodes (docs/task.md "The run's counts") with pymunk 7 collision
handlers (``space.on_collision`` begin / separate): an episode starts when the base first touches
an obstacle (or the target) and ends when it touches none; a new touch within ``EPISODE_GAP_US``
of the end continues the episode, so a long press is one contact and a slide along an edge whose
touch flickers is one contact, however many times pymunk begins and separates the pair.
Base-vs-target contacts are not counted while the object is held (it is then out of the space)
and count again once it is put down.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pymunk

from .scenario import ObstacleSpec, PathPoint, TargetSpec

COLL_BASE = 1
COLL_OBSTACLE = 2
COLL_TARGET = 3

GRAVITY_MPS2 = 9.81


@dataclass(frozen=True)
class TargetGeometry:
    """Physical size of a target kind (m).

    ``radius_m`` is the footprint for collisions, ``grip_width_m`` the width the fingers close
    on, ``grasp_height_m`` the height of the grasp point above the ground (on the object's axis)
    and ``height_m`` the top of the object.
    """

    radius_m: float
    height_m: float
    grip_width_m: float
    grasp_height_m: float
    mass_kg: float


TARGET_GEOMETRY: dict[str, TargetGeometry] = {
    # Sizes agree with mcu_sim/world/markers.py (what the camera draws).
    # 000: slender post (radius 20 mm) whose top card at 0.10 m carries the radial symbol;
    # grasped from above just under the card.
    "radial-symbol": TargetGeometry(0.020, 0.10, 0.040, 0.08, 0.15),
    # 002 guidance board on a thin post, graspable like a post.
    "double-cross": TargetGeometry(0.020, 0.10, 0.040, 0.08, 0.15),
    # 002: red cylinder (radius 25 mm, 0.12 m tall, rings about 0.06 m), grasped horizontally
    # (alpha = 0) at 0.10 m, 50 mm above 002's low shoulder (0.05 m, arm.py ARM_BY_METHOD): with
    # theta2 <= 0 a level fingertip never goes below the shoulder (docs/conventions.md).
    "red-cylinder": TargetGeometry(0.025, 0.12, 0.050, 0.10, 0.10),
}

TARGET_FRICTION_MU = 0.5
# the 002 guidance board's post (camera_scene.py draws it): 20 mm square, this far behind the
# cylinder's axis (markers.BOARD_BEHIND_M plus the 20 mm from the board's face to the post)
BOARD_POST_BEHIND_M = 0.17
BOARD_POST_SIDE_M = 0.02


EPISODE_GAP_US = 500_000  # touches less than this apart are one contact episode


@dataclass
class ContactEpisode:
    """One contact episode between the base and obstacles (or the target)."""

    start_us: int
    kind: str  # "obstacle" or "target"
    index: int  # obstacle index in the scenario of the first touch, -1 for the target
    end_us: int | None = None  # None while the base still touches

    def duration_us(self, now_us: int) -> int:
        return (now_us if self.end_us is None else self.end_us) - self.start_us


class ContactCounter:
    """Collision handlers that turn base-vs-obstacle and base-vs-target touches into episodes."""

    def __init__(self, space: pymunk.Space, clock):
        self.events: list[ContactEpisode] = []
        self.counts = {"obstacle": 0, "target": 0}
        self._touching = {"obstacle": 0, "target": 0}  # pairs in touch now
        self._open: dict[str, ContactEpisode | None] = {"obstacle": None, "target": None}
        self._clock = clock  # callable -> current simulated t_us
        self.count_target = True
        space.on_collision(COLL_BASE, COLL_OBSTACLE, begin=self._begin_obstacle,
                           separate=self._separate_obstacle)
        space.on_collision(COLL_BASE, COLL_TARGET, begin=self._begin_target,
                           separate=self._separate_target)

    def _begin(self, kind: str, index: int) -> None:
        self._touching[kind] += 1
        if self._touching[kind] > 1:
            return
        now, last = self._clock(), self._open[kind]
        if last is not None and last.end_us is not None and now - last.end_us < EPISODE_GAP_US:
            last.end_us = None  # the same episode goes on
            return
        ep = ContactEpisode(now, kind, index)
        self.events.append(ep)
        self._open[kind] = ep
        self.counts[kind] += 1

    def _separate(self, kind: str) -> None:
        if self._touching[kind] == 0:
            return
        self._touching[kind] -= 1
        ep = self._open[kind]
        if self._touching[kind] == 0 and ep is not None and ep.end_us is None:
            ep.end_us = self._clock()

    def _begin_obstacle(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data) -> None:
        shape = arbiter.shapes[1] if arbiter.shapes[0].collision_type == COLL_BASE \
            else arbiter.shapes[0]
        self._begin("obstacle", getattr(shape, "obstacle_index", -1))

    def _separate_obstacle(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data) -> None:
        self._separate("obstacle")

    def _begin_target(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data) -> None:
        if self.count_target:
            self._begin("target", -1)

    def _separate_target(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data) -> None:
        if self.count_target or self._touching["target"]:
            self._separate("target")

    def count(self, kind: str) -> int:
        """Number of contact episodes of ``kind`` ("obstacle" or "target")."""
        return self.counts[kind]

    def contact_time_s(self, kind: str) -> float:
        """Total time (s) of the episodes of ``kind``, an open one up to now."""
        now = self._clock()
        return sum(e.duration_us(now) for e in self.events if e.kind == kind) / 1e6


def add_obstacles(space: pymunk.Space, specs: tuple[ObstacleSpec, ...]) -> list[pymunk.Shape]:
    """Add every obstacle to the static body in scenario order; returns the shapes."""
    shapes: list[pymunk.Shape] = []
    body = space.static_body
    for i, o in enumerate(specs):
        if o.shape == "circle":
            shape = pymunk.Circle(body, o.radius_m, (o.x_m, o.y_m))
        elif o.shape == "box":
            c, s = math.cos(o.heading_rad), math.sin(o.heading_rad)
            hw, hd = o.width_m / 2, o.depth_m / 2
            # width along the heading, depth across it
            corners = [(o.x_m + c * dx - s * dy, o.y_m + s * dx + c * dy)
                       for dx, dy in ((-hw, -hd), (hw, -hd), (hw, hd), (-hw, hd))]
            shape = pymunk.Poly(body, corners)
        else:
            shape = pymunk.Segment(body, (o.x_m, o.y_m), (o.x2_m, o.y2_m), o.thickness_m / 2)
        shape.collision_type = COLL_OBSTACLE
        shape.friction = 0.7
        shape.obstacle_index = i
        space.add(shape)
        shapes.append(shape)
    return shapes


class TargetObject:
    """The graspable object: a pushable dynamic body, or a kinematic one dragged along a path."""

    def __init__(self, space: pymunk.Space, spec: TargetSpec):
        self.spec = spec
        self.geometry = TARGET_GEOMETRY[spec.kind]
        self.space = space
        self.path: tuple[PathPoint, ...] = spec.path
        g = self.geometry
        if self.path:
            self.body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        else:
            moment = pymunk.moment_for_circle(g.mass_kg, 0, g.radius_m)
            self.body = pymunk.Body(g.mass_kg, moment)
        self.body.position = (spec.x_m, spec.y_m)
        self.body.angle = spec.heading_rad
        self.shape = pymunk.Circle(self.body, g.radius_m)
        self.shape.collision_type = COLL_TARGET
        self.shape.filter = pymunk.ShapeFilter(categories=0b100)
        self.shape.friction = 0.5
        self.constraints: list[pymunk.Constraint] = []
        if not self.path:
            friction_n = TARGET_FRICTION_MU * g.mass_kg * GRAVITY_MPS2
            pivot = pymunk.PivotJoint(space.static_body, self.body, (0, 0), (0, 0))
            pivot.max_bias = 0
            pivot.max_force = friction_n
            gear = pymunk.GearJoint(space.static_body, self.body, 0.0, 1.0)
            gear.max_bias = 0
            gear.max_force = friction_n * g.radius_m
            self.constraints = [pivot, gear]
        space.add(self.body, self.shape, *self.constraints)
        self.in_space = True
        self.z_m = 0.0  # height of the object's base above the ground (lifted when grasped)
        # where the 002 board stands relative to (x, y, heading): it follows a cylinder on the
        # ground (carried with it by hand) and stays on its post once the cylinder is lifted
        self.board_place: tuple[float, float, float] | None = None
        self.post: pymunk.Shape | None = None
        if spec.kind == "red-cylinder":
            body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
            body.position = self._post_goal()
            half = BOARD_POST_SIDE_M / 2
            self.post = pymunk.Poly(body, [(-half, -half), (half, -half), (half, half),
                                           (-half, half)])
            self.post.collision_type = COLL_OBSTACLE
            self.post.friction = 0.7
            self.post.obstacle_index = -1  # a marker's post, not a scenario obstacle
            space.add(body, self.post)

    def _post_goal(self) -> tuple[float, float]:
        x, y = self.body.position
        h = self.body.angle
        return (x - BOARD_POST_BEHIND_M * math.cos(h), y - BOARD_POST_BEHIND_M * math.sin(h))

    def carry_post(self, horizon_us: int) -> None:
        """Move the board's post with a cylinder standing on the ground (by velocity, reaching
        its place behind the cylinder at t + horizon); still once the board stays put."""
        if self.post is None:
            return
        body = self.post.body
        if self.board_place is not None:
            body.velocity = (0.0, 0.0)
            return
        gx, gy = self._post_goal()
        x, y = body.position
        dt = horizon_us * 1e-6
        body.velocity = ((gx - x) / dt, (gy - y) / dt)

    def path_point(self, t_s: float) -> tuple[float, float] | None:
        """Linear interpolation of the path at ``t_s`` (None before the first way point)."""
        p = self.path
        if not p or t_s < p[0].t_s:
            return None
        if t_s >= p[-1].t_s:
            return p[-1].x_m, p[-1].y_m
        for a, b in zip(p, p[1:], strict=False):
            if a.t_s <= t_s < b.t_s:
                f = (t_s - a.t_s) / (b.t_s - a.t_s)
                return a.x_m + f * (b.x_m - a.x_m), a.y_m + f * (b.y_m - a.y_m)
        return p[-1].x_m, p[-1].y_m

    def drag(self, t_us: int, horizon_us: int) -> None:
        """Set the kinematic velocity that brings the object onto the path at t + horizon."""
        if not self.path or not self.in_space:
            return
        goal = self.path_point((t_us + horizon_us) * 1e-6)
        if goal is None:
            self.body.velocity = (0.0, 0.0)
            return
        x, y = self.body.position
        dt = horizon_us * 1e-6
        self.body.velocity = ((goal[0] - x) / dt, (goal[1] - y) / dt)

    def detach_from_space(self) -> None:
        """Take the object out of the plane (it is held by the gripper); the board, if any,
        stays where the object stood."""
        if self.board_place is None:
            x, y = self.body.position
            self.board_place = (float(x), float(y), float(self.body.angle))
        if self.in_space:
            self.space.remove(self.body, self.shape, *self.constraints)
            self.in_space = False
            self.path = ()

    def drop_at(self, x_m: float, y_m: float) -> None:
        """Put the object back on the ground at (x, y) at rest (released by the gripper)."""
        self.body.position = (x_m, y_m)
        self.body.velocity = (0.0, 0.0)
        self.body.angular_velocity = 0.0
        self.z_m = 0.0
        if not self.in_space:
            self.space.add(self.body, self.shape, *self.constraints)
            self.in_space = True

    def pose(self) -> tuple[float, float, float, float]:
        """(x_m, y_m, z_m, heading_rad) of the object's base centre."""
        x, y = self.body.position
        return float(x), float(y), self.z_m, float(self.body.angle)

    def grasp_point(self) -> tuple[float, float, float]:
        """World position of the grasp point on the object's axis."""
        x, y, z, _ = self.pose()
        return x, y, z + self.geometry.grasp_height_m
