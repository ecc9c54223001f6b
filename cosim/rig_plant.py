"""The plant as the rig sees it: the pymunk World plus the eye-in-hand camera renderer.

Adapts :class:`mobigrasp.mcu_sim.world.world.World` and the camera renderer
(mobigrasp.mcu_sim.world.camera) to :class:`mobigrasp.cosim.plant.Plant`. The camera's intrinsics
and image options come from the scenario's ``[camera]``; its noise is seeded by (world seed, capture
time), so a frame depends only on simulated state. Ground truth (:meth:`WorldPlant.truth`) goes to
the trace, never to the host.
"""

from __future__ import annotations

import math

import numpy as np

from mobigrasp.mcu_sim.world.camera import CameraOptions, Intrinsics, apply_options, render_clean
from mobigrasp.mcu_sim.world.scenario import Scenario
from mobigrasp.mcu_sim.world.world import World

STAND_STILL_RADIUS_M = 0.05  # the base's centre this near where it stopped: standing still
ARRIVED_M = 0.6  # the base's centre this near the object: the approach is over (the grasp's
# own stops, ADJUST's close look and 001's look before the grasp, are not stand-stills)


def _round(x: float, nd: int = 6) -> float | None:
    return None if x is None or not math.isfinite(x) else round(float(x), nd)


class WorldPlant:
    """World + camera behind the rig's plant interface."""

    def __init__(self, scenario: Scenario, seed: int | None = None) -> None:
        self.scenario = scenario
        # the run's trace samples truth itself (truth() below): the world's own 50 Hz recorder
        # would keep samples nobody reads
        self.world = World(scenario, seed, record_truth=False)
        cam = scenario.camera
        self.intrinsics = Intrinsics(f_px=cam.f_px, u0_px=cam.u0_px, v0_px=cam.v0_px)
        self.options = CameraOptions(noise_std=cam.noise_std, blur_px=cam.blur_px,
                                     brightness=cam.brightness)
        # The Plant calls of the rig's coupling step (cosim/rig.py) go straight to the
        # world: step_to (whole 1 ms physics steps), set_servo_pulse_us (a servo's pulse width
        # from the MCU's timer), set_wheel_duty (the motors' 8-bit PWM duties), encoder_ticks
        # (cumulative counts for the MCU). Bound here, not wrapped: one Python frame less per
        # call, several calls per coupling step.
        w = self.world
        self.step_to = w.step_to
        self.set_servo_pulse_us = w.set_servo_pulse_us
        self.set_wheel_duty = w.set_wheel_duty
        self.encoder_ticks = w.base.encoder_ticks
        self._sonar_us = -1
        # Without noise or dropout a sonar's range is a pure function of the space and the pose,
        # so the one the MCU fired is cast alone (it fires one at a time: casting all five per
        # trigger was 4/5 wasted). With noise the ring draws for all sensors in order, as before.
        c = self.world.sonar.config
        self._sonar_one_by_one = c.noise_std_m == 0.0 and c.dropout_p == 0.0
        self._sonar_one: dict[int, float | None] = {}
        self._clean_key: tuple | None = None
        self._clean: np.ndarray | None = None
        self._sonar: list[float | None] = []
        self.path_length_m = 0.0
        self._last_xy = self._xy()
        self._tip_error_mm: float | None = None
        self.final_error_mm: float | None = None  # fingertip to grasp point when it attached
        self.grasp_us: int | None = None
        # the longest stand-still of the search and the approach (docs/task.md "The run's
        # counts"): the base's centre within STAND_STILL_RADIUS_M of where it stopped, until it
        # first comes within ARRIVED_M of the object or the gripper first closes
        self.stand_still_max_us = 0
        self._still_since = (0, self._last_xy)  # (t_us, xy) where the present stand-still began
        self._approach_over = False
        self.close_alpha_rad: float | None = None  # the gripper's pitch as it closed (truth)
        self._open_m = self.world.arm.gripper_opening_m(0) - 1e-4

    def _xy(self) -> tuple[float, float]:
        x, y, _ = self.world.base.pose()
        return x, y

    # ---- Plant (with the calls bound in __init__) ------------------------------------
    def sonar_range_m(self, index: int) -> float | None:
        """Range of sonar ``index`` (ray casts done once per physics time, all sonars at once)."""
        w = self.world
        if self._sonar_one_by_one:
            if not 0 <= index < len(w.sonar.angles):
                return None
            if self._sonar_us != w.t_us:
                self._sonar_one.clear()
                self._sonar_us = w.t_us
            if index not in self._sonar_one:
                self._sonar_one[index] = w.sonar_range_m(int(index))
            return self._sonar_one[index]
        if self._sonar_us != w.t_us:
            self._sonar = list(w.sonar_ranges_m())
            self._sonar_us = w.t_us
        return self._sonar[index] if 0 <= index < len(self._sonar) else None

    def capture(self, t_us: int) -> np.ndarray:
        """The eye-in-hand camera's frame now (uint8 H x W x 3 RGB): camera.render, with the
        clean image reused while scene and pose are bit-identical (a standing robot and arm).

        Without degradations the frame is the clean image itself, read-only: the plant never
        writes into an image once rendered (a new view is a new array), so a frame handed out
        stays what it was without a 230 kB copy per frame, and a caller that tried to write
        into it would fail loudly instead of changing a later frame."""
        scene = self._render_clean()
        if self._plain:
            # no blur, gain or noise: apply_options would hand the image back as it is (seeding
            # its generator, ~50 us per frame, for nothing)
            return self._clean
        rng = np.random.default_rng([scene.seed & 0xFFFFFFFF, int(t_us) & 0xFFFFFFFFFFFF])
        # with any degradation on, apply_options returns a new array and never writes into
        # its input
        return apply_options(self._clean, self.options, rng)

    def preload(self) -> None:
        """Build what the first frame needs once (the floor texture, the markers' mip levels
        from disk) before the run's clock starts: the camera at t = 0 renders its clean image
        now. Changes no frame: the first capture reuses that image only when scene and pose
        are bit-identical, as every later capture does."""
        self._render_clean()

    def _render_clean(self):
        """Render the clean image of the camera's current view into ``_clean`` unless scene and
        pose are bit-identical to the last one's; returns the scene."""
        pos, R = self.world.camera_pose_world()
        scene = self.world.camera_scene()
        key = (scene, np.asarray(pos, np.float64).tobytes(), np.asarray(R, np.float64).tobytes())
        if key != self._clean_key:
            self._clean = render_clean(scene, pos, R, self.intrinsics)
            self._clean.flags.writeable = False  # handed out as it is (capture)
            self._clean_key = key
        return scene

    @property
    def options(self) -> CameraOptions:
        """The image degradations applied to every frame (scenario ``[camera]``)."""
        return self._options

    @options.setter
    def options(self, value: CameraOptions) -> None:
        self._options = value
        # what apply_options leaves unchanged (its three steps each test the same)
        self._plain = (not value.blur_px > 0.0 and value.brightness == 1.0
                       and not value.noise_std > 0.0)

    # ---- truth for the trace ------------------------------------------------------------
    def sample_path(self) -> None:
        """Accumulate the base path length (called by the runner once per quantum)."""
        x, y = self._xy()
        self.path_length_m += math.hypot(x - self._last_xy[0], y - self._last_xy[1])
        self._last_xy = (x, y)
        w = self.world
        if not self._approach_over:
            ox, oy, _, _ = w.target.pose()
            self._approach_over = math.hypot(x - ox, y - oy) <= ARRIVED_M
        if not self._approach_over:
            since_us, at = self._still_since
            if math.hypot(x - at[0], y - at[1]) > STAND_STILL_RADIUS_M:
                self._still_since = (w.t_us, (x, y))
            else:
                self.stand_still_max_us = max(self.stand_still_max_us, w.t_us - since_us)
        if w.attached:
            self._approach_over = True
            if self.grasp_us is None:
                self.grasp_us = w.t_us
                self.final_error_mm = self._tip_error_mm
                self.close_alpha_rad = self._alpha_rad()
        elif w.arm.gripper_opening_m(w.t_us) < self._open_m:  # closing: measure the error
            self._approach_over = True
            if self.grasp_us is None:
                self.close_alpha_rad = self._alpha_rad()
            tip = w.arm.fingertip_world(w.base.pose(), w.t_us)
            gp = w.target.grasp_point()
            self._tip_error_mm = 1000.0 * math.dist((float(tip[0]), float(tip[1]),
                                                     float(tip[2])), gp)

    def robot_geometry(self) -> dict:
        """The footprint, the safety circle R_r (001's parameter, null for the others) and the
        sonar ring (k_s cones of A_g up to D_e), for drawing the run."""
        w, c = self.world, self.world.sonar.config
        r_r = self.scenario.params.get("R_r") if self.scenario.meta.method == "001" else None
        return {"footprint_m": w.base.radius_m, "safety_radius_m": r_r,
                "sonar": {"k_s": c.k_s, "A_g_rad": c.A_g, "D_e_m": c.D_e}}

    def _alpha_rad(self) -> float:
        """The gripper's pitch below the horizontal's sign convention of arm.py (q2 + q3 + q4,
        eq. (4) of 002: 0 is level)."""
        q = self.world.arm.joints(self.world.t_us)
        return float(q[2] + q[3] + q[4])

    def truth(self, t_us: int) -> dict:
        """Compact ground-truth sample for the trace (rounded: the trace stays small)."""
        t = self.world.truth()
        b, o = t["base"], t["object"]
        return {
            "x_m": _round(b["x_m"]), "y_m": _round(b["y_m"]),
            "heading_rad": _round(b["heading_rad"]),
            "joints_rad": [_round(q, 5) for q in t["joints_rad"]],
            "obj": [_round(o["x_m"]), _round(o["y_m"]), _round(o["z_m"])],
            "camera_m": [_round(c) for c in t["camera_m"]],
            "attached": bool(t["attached"]),
            "collisions": t["collisions"],
            "min_clearance_m": _round(t["min_clearance_m"]) if t["min_clearance_m"] is not None
            else None,
        }

    def final(self) -> dict:
        """Figures for the summary from the world's ground truth at the end."""
        t = self.world.truth()
        return {"grasped": bool(t["attached"]), "grasps": t["grasps"],
                "collisions": t["collisions"], "contact_time_s": t["contact_time_s"],
                "min_obstacle_clearance_m": t["min_clearance_m"],
                "stand_still_max_s": self.stand_still_max_us / 1e6,
                "object": t["object"], "base": t["base"],
                "path_length_m": self.path_length_m, "final_error_mm": self.final_error_mm,
                "grasp_us": self.grasp_us, "close_alpha_rad": self.close_alpha_rad}
