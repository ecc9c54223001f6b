"""The plant: one pymunk space with the base, obstacles, target, arm and sonars, stepped at 1 kHz.

``World(scenario, seed)`` builds the space in a fixed insertion order (obstacles in scenario
order, then the base, then the target and the 002 board's post; pymunk#181: order decides the
solver's results).
``step_to(t_us)`` advances whole 1 ms physics steps up to ``t_us`` (the world's time is always a
multiple of 1 ms; inputs set between steps act from the next step), so the result depends only
on the inputs and their times, never on how finely the caller slices time.

Every ``TICK_US`` = 10 ms of simulated time the world also: drags a moving target along its
``[[target.path]]``, applies the grasp rule of arm.py (attach / carry / release), tracks the
minimum obstacle clearance, and lets the truth recorder sample.

Inputs: ``set_servo_pulse_us(ch, pulse_us)``, ``set_wheel_duty(left, right)``.
Outputs (what sensors see): ``encoder_ticks()``, ``sonar_ranges_m()`` / ``sonar_range_m(i)``,
``camera_pose_world()``, ``camera_scene()`` (the renderer's own Scene type) and ``scene()``
(plain dataclasses with heights and the lifted object). Truth (never for the host): ``truth()``,
``joint_angles_rad()``, ``gripper_grasped()``, ``recorder``.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass

import numpy as np
import pymunk

from .arm import ARM_BY_METHOD, GRASP_ALPHA_BY_METHOD, Arm, grasp_ok
from .base import PHYSICS_DT_US, DiffDriveBase, new_space
from .obstacles import ContactCounter, TargetObject, add_obstacles
from .scenario import CameraSpec, Scenario
from .sonar import SonarConfig, SonarRing
from .truth import TruthRecorder

TICK_US = 10_000
TICK_STEPS = TICK_US // PHYSICS_DT_US
OBSTACLE_CATEGORY = 0b10
CLEARANCE_MAX_M = 10.0
_OBSTACLES_ONLY = pymunk.ShapeFilter(mask=OBSTACLE_CATEGORY)


@dataclass(frozen=True)
class SceneObstacle:
    """An obstacle for drawing: shape "circle" | "box" | "wall", pose and size (m)."""

    shape: str
    x_m: float
    y_m: float
    heading_rad: float
    height_m: float
    radius_m: float | None = None
    width_m: float | None = None
    depth_m: float | None = None
    x2_m: float | None = None
    y2_m: float | None = None
    thickness_m: float | None = None


@dataclass(frozen=True)
class SceneTarget:
    """The target for drawing: kind, pose of its base centre (z > 0 when lifted), size (m)."""

    kind: str
    x_m: float
    y_m: float
    z_m: float
    heading_rad: float
    radius_m: float
    height_m: float
    attached: bool


@dataclass(frozen=True)
class Scene:
    """What the camera renderer needs at one instant."""

    t_us: int
    target: SceneTarget
    obstacles: tuple[SceneObstacle, ...]
    camera: CameraSpec
    base_pose: tuple[float, float, float]
    base_radius_m: float


class World:
    """The simulated plant of one scenario run."""

    def __init__(self, scenario: Scenario, seed: int | None = None,
                 sonar: SonarConfig | None = None, truth_rate_hz: int = 50,
                 record_truth: bool = True):
        self.scenario = scenario
        self.seed = scenario.meta.seed if seed is None else int(seed)
        robot = scenario.meta.robot
        self.space: pymunk.Space = new_space()
        self.obstacle_shapes = add_obstacles(self.space, scenario.obstacles)
        for shape in self.obstacle_shapes:
            shape.filter = pymunk.ShapeFilter(categories=OBSTACLE_CATEGORY)
        r = scenario.robot
        self.base = DiffDriveBase(self.space, r.x_m, r.y_m, r.heading_rad)
        self.target = TargetObject(self.space, scenario.target)
        if self.target.post is not None:  # the board's post: an obstacle to base and sonars
            self.target.post.filter = pymunk.ShapeFilter(categories=OBSTACLE_CATEGORY)
        self._steps = 0
        self.contacts = ContactCounter(self.space, self._contact_time_us)
        self.arm = Arm(ARM_BY_METHOD[robot])
        self.alpha_grasp = GRASP_ALPHA_BY_METHOD[robot]
        if sonar is None:
            p = scenario.params
            sonar = (SonarConfig(k_s=p["k_s"], A_g=p["A_g"], D_e=p["D_e"])
                     if robot == "001" else SonarConfig())
        self.sonar = SonarRing(sonar, self.child_rng("sonar"))
        self.attached = False
        self.grasp_count = 0
        self._last_opening_m = self.arm.gripper_opening_m(0)
        self.min_clearance_m = math.inf
        self._clearance_at = (0.0, 0.0, -math.inf)  # (x, y, clearance) of the last query
        self.recorder = TruthRecorder(truth_rate_hz, TICK_US)
        self._camera_obstacles_cache: tuple | None = None  # camera_scene's, built on first use
        self._record_truth = record_truth  # False: the recorder stays empty (a caller that
        # samples truth() itself, like the run's plant, saves a truth() per 20 ms)
        self._tick()

    # ---- time ---------------------------------------------------------------------------
    @property
    def t_us(self) -> int:
        """Simulated time of the last physics step (a multiple of 1000 us)."""
        return self._steps * PHYSICS_DT_US

    def _contact_time_us(self) -> int:
        return self.base.steps * PHYSICS_DT_US

    def child_rng(self, name: str) -> np.random.Generator:
        """An independent generator for a named consumer, fixed by the world seed and the name."""
        key = zlib.crc32(name.encode("utf-8"))
        return np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(key,)))

    def step_to(self, t_us: int) -> None:
        """Advance whole 1 ms physics steps until the next step would pass ``t_us``."""
        if type(t_us) is not int and (isinstance(t_us, bool) or not isinstance(t_us, int)):
            raise TypeError(f"World.step_to: t_us must be an int of microseconds, got {t_us!r}")
        steps = self._steps
        if t_us < steps * PHYSICS_DT_US:
            raise ValueError(f"World.step_to: time went backwards ({t_us} < {self.t_us} us)")
        last = t_us // PHYSICS_DT_US
        run = self.base.run_steps
        while steps < last:
            next_tick = (steps // TICK_STEPS + 1) * TICK_STEPS
            n = (next_tick if next_tick < last else last) - steps
            run(n)
            steps += n
            self._steps = steps
            if steps == next_tick:
                self._tick()

    def _tick(self) -> None:
        t = self.t_us
        self.target.drag(t, TICK_US)
        self.target.carry_post(TICK_US)
        self._update_grasp(t)
        self._update_clearance()
        if self._record_truth:
            self.recorder.on_tick(self, t)

    # ---- inputs -------------------------------------------------------------------------
    def set_servo_pulse_us(self, ch: int, pulse_us: float) -> None:
        """A servo pulse width on channel ``ch`` (0 gripper .. 5 waist), from now on."""
        self.arm.set_pulse_us(ch, pulse_us, self.t_us)

    def set_wheel_duty(self, left: int, right: int) -> None:
        """Signed motor duties -255..255 (clamped; bad values counted by the motors)."""
        self.base.set_duty(left, right)

    # ---- sensor outputs -----------------------------------------------------------------
    def encoder_ticks(self) -> tuple[int, int]:
        """Cumulative quadrature counts (left, right), 1024 per wheel revolution."""
        return self.base.encoder_ticks()

    def sonar_ranges_m(self) -> list[float | None]:
        """One range per sonar (m), None when there is no echo within D_e."""
        return self.sonar.read(self.space, self.base.pose())

    def sonar_range_m(self, index: int) -> float | None:
        """Range of one sonar (0-based index), None when there is no echo within D_e."""
        return self.sonar.read_one(self.space, self.base.pose(), index)

    def camera_pose_world(self) -> tuple[np.ndarray, np.ndarray]:
        """(position (3,), R_wc (3, 3)); R_wc columns = camera x right, y down, z optical axis."""
        return self.arm.camera_pose_world(self.base.pose(), self.t_us)

    def scene(self) -> Scene:
        """Geometry for the camera renderer at the current time."""
        x, y, z, h = self.target.pose()
        g = self.target.geometry
        tgt = SceneTarget(self.target.spec.kind, x, y, z, h, g.radius_m, g.height_m,
                          self.attached)
        obs = tuple(SceneObstacle(o.shape, o.x_m, o.y_m, o.heading_rad, o.height_m, o.radius_m,
                                  o.width_m, o.depth_m, o.x2_m, o.y2_m, o.thickness_m)
                    for o in self.scenario.obstacles)
        return Scene(self.t_us, tgt, obs, self.scenario.camera, self.base.pose(),
                     self.base.radius_m)

    def camera_scene(self):
        """The scene in the renderer's own types (mcu_sim.world.camera_scene.Scene).

        Walls become thin boxes (the renderer draws circles and boxes). A held target is drawn
        where the gripper holds it (lifted), the 002 board where the cylinder stood.
        """
        from . import camera_scene as cs  # imported here: the renderer is optional for physics

        x, y, z, h = self.target.pose()
        return cs.Scene(target=cs.Target(self.target.spec.kind, x, y, h, z,
                                         self.target.board_place),
                        obstacles=self._camera_obstacles(), seed=self.seed)

    def _camera_obstacles(self) -> tuple:
        """The obstacles in the renderer's types, built once (they never move; a frame's scene
        used to build and validate them again for every capture)."""
        if self._camera_obstacles_cache is not None:
            return self._camera_obstacles_cache
        from . import camera_scene as cs

        obstacles = []
        for o in self.scenario.obstacles:
            if o.shape == "circle":
                obstacles.append(cs.Obstacle("circle", o.x_m, o.y_m, radius_m=o.radius_m,
                                             height_m=o.height_m))
            elif o.shape == "box":
                obstacles.append(cs.Obstacle("box", o.x_m, o.y_m, width_m=o.width_m,
                                             depth_m=o.depth_m, heading_rad=o.heading_rad,
                                             height_m=o.height_m))
            else:
                length = math.hypot(o.x2_m - o.x_m, o.y2_m - o.y_m)
                obstacles.append(cs.Obstacle(
                    "box", 0.5 * (o.x_m + o.x2_m), 0.5 * (o.y_m + o.y2_m), width_m=length,
                    depth_m=o.thickness_m, heading_rad=math.atan2(o.y2_m - o.y_m, o.x2_m - o.x_m),
                    height_m=o.height_m))
        self._camera_obstacles_cache = tuple(obstacles)
        return self._camera_obstacles_cache

    # ---- truth --------------------------------------------------------------------------
    def joint_angles_rad(self) -> list[float]:
        """[theta0 (gripper closure 0..1), theta1 .. theta5 (rad)] as the servos really are."""
        return self.arm.joints(self.t_us)

    def gripper_grasped(self) -> bool:
        """True while the object is held by the gripper."""
        return self.attached

    def truth(self) -> dict:
        """Ground truth now: base pose, joints, object, grasp, contacts, clearance."""
        x, y, h = self.base.pose()
        v, w = self.base.velocity()
        ox, oy, oz, oh = self.target.pose()
        q = self.arm.joints(self.t_us)
        cam = self.arm.fingertip_world((x, y, h), self.t_us, q)
        return {
            "t_us": self.t_us,
            "base": {"x_m": x, "y_m": y, "heading_rad": h, "v_mps": v, "w_radps": w},
            "joints_rad": q,
            "gripper_opening_m": self.arm.gripper_opening_m(self.t_us),
            "camera_m": list(cam),
            "object": {"x_m": ox, "y_m": oy, "z_m": oz, "heading_rad": oh},
            "attached": self.attached,
            "grasps": self.grasp_count,
            "collisions": dict(self.contacts.counts),  # contact episodes (obstacles.py)
            "contact_time_s": {k: self.contacts.contact_time_s(k) for k in self.contacts.counts},
            "min_clearance_m": None if math.isinf(self.min_clearance_m)
            else self.min_clearance_m,
            "encoder_ticks": list(self.encoder_ticks()),
        }

    # ---- tick work ----------------------------------------------------------------------
    def _update_grasp(self, t_us: int) -> None:
        opening = self.arm.gripper_opening_m(t_us)
        width = self.target.geometry.grip_width_m
        if self.attached:
            tip = self.arm.fingertip_world(self.base.pose(), t_us)
            if opening >= width:
                self.attached = False
                self.target.drop_at(tip[0], tip[1])
                self.contacts.count_target = True  # back on the ground: a bump is a contact
                self.base.space_changed = True
            else:
                self.target.body.position = (tip[0], tip[1])
                self.target.z_m = tip[2] - self.target.geometry.grasp_height_m
        elif self._last_opening_m >= width > opening:
            tip = self.arm.fingertip_world(self.base.pose(), t_us)
            q = self.arm.joints(t_us)
            if grasp_ok(tip, self.target.grasp_point(), q[2] + q[3] + q[4], self.alpha_grasp):
                self.attached = True
                self.grasp_count += 1
                self.contacts.count_target = False
                self.target.detach_from_space()
                self.base.space_changed = True
        self._last_opening_m = opening

    def _update_clearance(self) -> None:
        """Track the minimum clearance between the footprint and any obstacle.

        The clearance is 1-Lipschitz in the base position (obstacles are static), so while
        ``last clearance - distance moved since`` stays above the minimum so far, no new minimum
        is possible and the space query is skipped.
        """
        if not self.obstacle_shapes and self.target.post is None:
            return
        x, y, _ = self.base.pose()
        lx, ly, last = self._clearance_at
        if last - math.hypot(x - lx, y - ly) > self.min_clearance_m:
            return
        hit = self.space.point_query_nearest((x, y), CLEARANCE_MAX_M, _OBSTACLES_ONLY)
        now = math.inf if hit is None else hit.distance - self.base.radius_m
        self._clearance_at = (x, y, now)
        self.min_clearance_m = min(self.min_clearance_m, now)
