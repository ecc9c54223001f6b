"""The task state machine of the move-to-grasp (000 §II-III, 001 §III, 002 §1): pure logic.

    SEARCH -> APPROACH -> ADJUST -> ROUGH_GRASP -> PRECISE_GRASP -> LIFT -> DONE
    ADJUST (vision lost) -> LOST -> SEARCH;  any state -> FAILED(reason)

- SEARCH: the arm search of 000 Fig. 5 (host.search), base turns between cycles; looks for the
  radial symbol (000, 001) or the double cross (002).
- APPROACH: 000 / 001 follow the best Bezier path (host.planning, host.control.path_follow;
  001 replans from the present pose and velocity with fresh sonar every ``replan_period_us``)
  while the posture adjustment (host.posture, eq. (10) of 000) keeps the object in view from
  the odometry estimate; 002 steers with the fuzzy controller on the double cross's e.
- ADJUST: 000 / 001 the vision-based approaching adjustment with the dual "+"; 002 "slows down
  and goes straight with posture adjustment" (002 §1) until the red cylinder's ring spacing
  d_pixel > T_d = 45.
- ROUGH_GRASP: IK of eq. (11) of 000 (alpha_T = -pi/2) or eq. (4) of 002 (horizontal) from the
  last object position.  PRECISE_GRASP: 000's roll to pi/2, k_T -> 0 by theta5, w_T in
  [20, 40] px, then down and close; 002 moves in from the pre-grasp point and closes.
- LIFT: raise the closed gripper; DONE when the arm has settled with the object held.

Every transition is a :class:`TaskEvent` (t_us, from, to, why) in simulated time; every state
has a timeout in simulated time (``timeouts_us``).  No I/O and no clock: the caller passes
``now_us`` and :class:`TaskInputs`; :class:`TaskOutputs` carry the commands.  Bad inputs are
counted (``Task.counters``) and dropped; joint targets always lie within host.arm_calib limits.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from typing import Any

from mobigrasp.host import arm_calib
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.kinematics import PAPER_000, PAPER_002, ArmGeometry
from mobigrasp.host.task_sense import CAMERA_000, CAMERA_002
from mobigrasp.host.task_states import TaskStates

STATES = ("SEARCH", "APPROACH", "ADJUST", "ROUGH_GRASP", "PRECISE_GRASP", "LIFT", "DONE",
          "LOST", "FAILED")
METHODS = ("000", "001", "002")
TERMINAL = ("DONE", "FAILED")

# Detectors each state runs (names shared with the host app's detector table).
DETECTORS: dict[str, dict[str, list[str]]] = {
    "000": {"SEARCH": ["radial_symbol"], "APPROACH": ["radial_symbol"],
            "ADJUST": ["dual_plus", "radial_symbol"], "PRECISE_GRASP": ["spoke"],
            "LIFT": ["dual_plus", "radial_symbol"]},  # LIFT: the grasp check (task_grasp)
    "002": {"SEARCH": ["double_cross"], "APPROACH": ["double_cross", "red_cylinder"],
            "ADJUST": ["red_cylinder"], "LIFT": ["red_cylinder"]},
}
DETECTORS["001"] = DETECTORS["000"]

DEFAULT_TIMEOUTS_US = {
    "SEARCH": 180_000_000, "APPROACH": 120_000_000, "ADJUST": 60_000_000,
    "ROUGH_GRASP": 8_000_000, "PRECISE_GRASP": 30_000_000, "LIFT": 8_000_000,
    "LOST": 5_000_000,
}


@dataclass(frozen=True)
class TaskParams:
    """Task parameters (integer mm, mrad, us); papers' values where they give one."""

    timeouts_us: dict = field(default_factory=lambda: dict(DEFAULT_TIMEOUTS_US))
    mount_forward_mm: int = 100  # waist axis ahead of the wheel axle (mcu_sim/world/arm.py)
    h_shoulder_mm: int = 200  # 000; 001: 108; 002: 50 (mcu_sim/world/arm.py ARM_BY_METHOD)
    object_top_mm: int = 100  # object top above the ground (000 card; 002 cylinder 120)
    grasp_height_mm: int = 80  # grasp point above the ground
    hover_mm: int = 110  # rough grasp: camera this far above the object top (000)
    lift_mm: int = 60
    approach_standoff_mm: int = 400  # 000 P3: axle this far from the object
    grasp_r_mm: int = 110  # object this far ahead of the waist axis for the grasp
    grasp_r_tol_mm: int = 20
    bearing_tol_mrad: int = 60
    adjust_vmax_mmps: int = 80
    adjust_theta3_mrad: int = -1000  # ADJUST close-look posture (task_states.enter_ADJUST)
    adjust_theta4_mrad: int = 1571
    blind_finish_mm: int = 80  # ADJUST may finish on odometry within this of its goal
    lost_timeout_us: int = 1_500_000
    blind_approach_mm: int = 1000  # 002: drive on toward the marker's last bearing this far
    blind_approach_us: int = 8_000_000  # ... and at most this long (1 m at 0.15 m/s: 6.7 s)
    blind_keep_mm: int = 700  # ... but stop it this short of the board's distance (crosses)
    lost_hold_us: int = 500_000
    max_lost: int = 5
    turn_wheel_mmps: int = 80
    wander_mmps: int = 200  # SEARCH wander speed (host.search); the planners' v_max is 250
    wander_clear_mm: int = 500  # a wander stops when a front sonar sees something this close
    sighting_match_mm: int = 200  # SEARCH: an unconfirmed sighting seen again this close is it
    replan_period_us: int = 300_000  # 001: sonar check of the rest of the path (replan.py)
    sonar_sweep_us: int = 200_000  # 001: first plan after one sweep of the 5 sonars (5 x 30 ms)
    sonar_offset_mm: int = 170  # 001: sonars on the 0.17 m footprint circle (mcu_sim/world/sonar)
    # 001: two neighbours' echoes this close are one echo in their overlap; their mounts on the
    # 0.17 m circle are 2 x 0.17 sin(pi/8) = 130 mm apart, so one point's ranges differ that much
    sonar_shared_echo_mm: int = 130
    replan_shift_mm: int = 150  # 000: replan when the object estimate moved this far
    max_plan_attempts: int = 3
    direct_max_mm: int = 1200  # no feasible curve after all attempts: ADJUST if this close
    max_detours: int = 6  # 001: drive aside (host.task_wander) this often before giving up
    detour_mm: int = 500  # length of one drive aside
    detour_clear_mm: int = 900  # a sonar reading at least this is a free direction
    servo_speed_mrad_per_s: int = 3000  # for settle times
    settle_margin_us: int = 300_000
    posture_step_mrad: int = 20  # per control step (1 rad/s at 50 Hz: the servos follow)
    frame_latency_us: int = 50_000  # a detection shows the scene this long ago (capture+vision)
    confirm_us: int = 700_000  # SEARCH: hold the pose this long to see the object again
    spoke_wait_us: int = 3_000_000  # no spoke for this long: grasp on the rough position
    precise_max_steps: int = 30
    precise_align_ch: int = 1  # joint that drives k_T to 0: 1 wrist roll, 5 waist (task_grasp)
    pregrasp_back_mm: int = 50  # 002: pre-grasp point this far short of the object
    grasp_close_timeout_us: int = 2_000_000
    cylinder_near_px: int = 12  # 002: ring spacing at which ADJUST (slow, straight) starts
    cross_near_px: int = 75  # 002: crosses this far apart (board ~0.6 m) place the cylinder
    slow_mmps: int = 60  # 002 ADJUST speed
    t_d_px: int = 45  # 002 T_d
    object_xy_mm: tuple = ()  # 001: P_i given in the odometry frame (skips SEARCH); () unknown
    search: dict = field(default_factory=dict)  # host.search.SearchParams fields
    posture: dict = field(default_factory=dict)  # host.posture.PostureParams fields
    planner: dict = field(default_factory=dict)  # Params000 / Params001 fields
    fuzzy: dict = field(default_factory=dict)  # host.control.fuzzy.FuzzyParams fields

    @classmethod
    def for_method(cls, method: str, overrides: dict | None = None) -> TaskParams:
        """Defaults for a method, then ``overrides`` (unknown key -> ValueError naming it)."""
        base = cls()
        if method == "001":
            # the long 001 arm puts the camera ahead of a close object: finish on odometry sooner
            base = replace(base, h_shoulder_mm=108, grasp_r_mm=130, hover_mm=90,
                           blind_finish_mm=250, max_plan_attempts=6)
        elif method == "002":
            # the level gripper of 002 (eq. (4)) with theta2 <= 0 reaches the grasp point 50 mm
            # above the low shoulder only 230..275 mm ahead of the waist (pitch 0..-0.28 rad):
            # stop the base 255 +- 15 mm short and come in from 40 mm short of the axis
            base = replace(base, h_shoulder_mm=50, object_top_mm=120, grasp_height_mm=100,
                           grasp_r_mm=255, grasp_r_tol_mm=15, pregrasp_back_mm=40,
                           # the double cross stands upright, far: the paper's first cycle,
                           # then the level look (f = 350 px: 0.66 rad vertical field)
                           search={"dense_cycles": 1, "coarse_theta2_mrad": (-2100, -2400)})
        overrides = dict(overrides or {})
        known = {f.name: f for f in fields(cls)}
        for key, value in list(overrides.items()):
            if key not in known:
                raise ValueError(f"unknown task parameter {key!r}; known: {sorted(known)}")
            default = getattr(base, key)
            if isinstance(default, dict):
                if not isinstance(value, dict):
                    raise ValueError(f"task parameter {key!r} must be a table, got {value!r}")
                if key == "timeouts_us":
                    bad = [s for s in value if s not in DEFAULT_TIMEOUTS_US]
                    if bad:
                        raise ValueError(f"timeouts_us: unknown state(s) {bad}")
                if key in ("timeouts_us", "search"):  # on top of the method's defaults
                    overrides[key] = {**default, **value}
            elif key == "object_xy_mm":
                if len(value) not in (0, 2) or not all(
                        isinstance(v, int) and not isinstance(v, bool) for v in value):
                    raise ValueError(f"object_xy_mm must be two ints (mm) or empty, got {value!r}")
                overrides[key] = tuple(value)
            elif not isinstance(value, int) or isinstance(value, bool):
                raise ValueError(f"task parameter {key!r} must be an int, got {value!r}")
        return replace(base, **overrides) if overrides else base


@dataclass(frozen=True)
class TaskInputs:
    """What the host knows at one control step (see module docstring of host.task)."""

    joints_mrad: tuple | None = None  # six joint angles from telemetry (host.arm_calib)
    x_mm: int = 0  # odometry pose of the wheel-axle midpoint
    y_mm: int = 0
    heading_mrad: int = 0
    v_mmps: int = 0
    sonar_mm: tuple = ()
    detections: dict = field(default_factory=dict)  # this frame's results; {} = no new frame
    grasp_closed: bool = False

    @classmethod
    def every_field(cls, *, joints_mrad: tuple | None, x_mm: int, y_mm: int, heading_mrad: int,
                    v_mmps: int, sonar_mm: tuple, detections: dict,
                    grasp_closed: bool) -> TaskInputs:
        """``TaskInputs(...)`` with all eight fields given, built without the generated
        __init__ (a frozen dataclass sets each field through object.__setattr__): the host
        builds one every control tick (host.app_factory.InputBuilder). Equal to the
        constructor's result (tests/test_task.py)."""
        obj = object.__new__(cls)
        obj.__dict__.update(joints_mrad=joints_mrad, x_mm=x_mm, y_mm=y_mm,
                            heading_mrad=heading_mrad, v_mmps=v_mmps, sonar_mm=sonar_mm,
                            detections=detections, grasp_closed=grasp_closed)
        return obj


@dataclass(frozen=True)
class TaskEvent:
    """One state transition."""

    t_us: int
    from_state: str
    to_state: str
    why: str


@dataclass
class TaskOutputs:
    """Commands for this step (None = leave as is), events, state and trace detail."""

    servo_mrad: tuple | None
    wheels_mmps: tuple | None
    gripper_permille: int | None
    events: list
    state: str
    detail: dict
    ops: OpCounts = field(default_factory=OpCounts)


class Task(TaskStates):
    """The move-to-grasp state machine for one method ("000", "001" or "002")."""

    def __init__(self, method: str, params: dict | None = None,
                 link_lengths_mm: tuple | None = None, start_us: int = 0) -> None:
        if method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got {method!r}")
        self.method = method
        self.p = TaskParams.for_method(method, params)
        if link_lengths_mm is None:
            link_lengths_mm = {"000": (95.5, 89.0, 97.0), "001": (160.0, 160.0, 200.0),
                               "002": (97.0, 89.0, 95.5)}[method]
        if len(link_lengths_mm) != 3 or min(link_lengths_mm) <= 0:
            raise ValueError(f"link_lengths_mm must be three positive lengths, "
                             f"got {link_lengths_mm!r}")
        self.geom: ArmGeometry = ArmGeometry.from_mm(*link_lengths_mm)
        if tuple(link_lengths_mm) == (95.5, 89.0, 97.0):
            self.geom = PAPER_000
        elif tuple(link_lengths_mm) == (97.0, 89.0, 95.5):
            self.geom = PAPER_002
        self.cam = CAMERA_002 if method == "002" else CAMERA_000
        self.state = "SEARCH"
        self.entered_us = int(start_us)
        self.counters = {"bad_inputs": 0, "bad_detections": 0, "lost": 0, "plans": 0}
        self._events: list[TaskEvent] = []
        self._detail: dict = {}
        self._ops = OpCounts()
        self.init_states(int(start_us))

    # --- bookkeeping used by the state handlers -------------------------------------------
    def go(self, now_us: int, to: str, why: str) -> None:
        """Transition (logged); entering a state runs its entry action on the next step."""
        if to not in STATES:
            raise ValueError(f"unknown state {to!r}")
        self._events.append(TaskEvent(int(now_us), self.state, to, why))
        self.state = to
        self.entered_us = int(now_us)
        self.entry_pending = True

    def fail(self, now_us: int, reason: str) -> None:
        """Transition to FAILED with a reason."""
        self.failure = reason
        self.go(now_us, "FAILED", reason)

    def note(self, **kw: Any) -> None:
        """Add to this step's trace detail."""
        self._detail.update(kw)

    def charge(self, ops: OpCounts) -> None:
        """Add modelled ARM9 work done in this step (planning)."""
        self._ops = self._ops + ops

    def detectors_needed(self) -> list[str]:
        """The detectors the current state uses (so the host runs and pays for only these)."""
        if self.state == "SEARCH" and self.search is not None and self.search.turning \
                and not self.search.wandering:  # blind while turning; looking while wandering
            return []
        return list(DETECTORS[self.method].get(self.state, []))

    # --- the step ---------------------------------------------------------------------------
    def _clean(self, inp: TaskInputs) -> tuple[TaskInputs, dict]:
        """Count and drop malformed inputs; returns usable inputs and detections."""
        joints = inp.joints_mrad
        x, y, h, v = pose = (inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps)
        dets = inp.detections
        # The usual inputs (host.app_factory.InputBuilder) are already clean: plain ints, a
        # tuple of six plain ints, a dict. Cleaning would rebuild an equal TaskInputs: skip it.
        if (type(dets) is dict and type(x) is int and type(y) is int and type(h) is int
                and type(v) is int
                and (joints is None or (type(joints) is tuple and len(joints) == 6
                                        and set(map(type, joints)) == {int}))):
            self.last_pose = pose
            return inp, dets
        if joints is not None:
            try:
                if len(joints) != 6:
                    raise ValueError("need 6 joints")
                joints = tuple(int(v) for v in joints)
            except (TypeError, ValueError):
                self.counters["bad_inputs"] += 1
                joints = None
        dets = inp.detections if isinstance(inp.detections, dict) else {}
        if not isinstance(inp.detections, dict):
            self.counters["bad_inputs"] += 1
        try:
            pose = tuple(int(v) for v in (inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps))
        except (TypeError, ValueError):
            self.counters["bad_inputs"] += 1
            pose = (self.last_pose[0], self.last_pose[1], self.last_pose[2], 0)
        self.last_pose = pose
        return replace(inp, joints_mrad=joints, x_mm=pose[0], y_mm=pose[1],
                       heading_mrad=pose[2], v_mmps=pose[3]), dets

    def step(self, now_us: int, inputs: TaskInputs) -> TaskOutputs:
        """Advance the task to ``now_us`` (simulated) with this step's inputs."""
        if not isinstance(inputs, TaskInputs):
            raise TypeError(f"Task.step needs TaskInputs, got {type(inputs).__name__}")
        now_us = int(now_us)
        self._events, self._detail, self._ops = [], {}, OpCounts()
        inp, dets = self._clean(inputs)
        # joints from telemetry; without telemetry assume the arm is where it was sent
        self.joints = inp.joints_mrad if inp.joints_mrad is not None else tuple(self.arm)
        if self.state not in TERMINAL:
            limit = self.p.timeouts_us.get(self.state)
            if limit is not None and now_us - self.entered_us >= limit:
                self.fail(now_us, f"timeout: {self.state} exceeded {limit} us")
        if self.state not in TERMINAL:
            self.run_state(now_us, inp, dets)
            self.remember(now_us, inp)
        if self.state in TERMINAL:
            self.wheels = (0, 0)
        servo = arm_calib.clamp_joints_mrad((self.gripper,) + tuple(self.arm[1:]))
        return TaskOutputs(servo, self.wheels, self.gripper, list(self._events), self.state,
                           dict(self._detail), self._ops)
