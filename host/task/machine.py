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

This module is the machine: the states, their transitions and timeouts, and the bookkeeping the
states share (arm targets and their settle time, the history of arm targets and base poses, the
object estimate in the odometry frame, the posture adjustment toward it). The states' entry
actions and steps are in one module per group (search.py: SEARCH and LOST, approach.py: the
path approach of 000/001, adjust.py, grasp.py: ROUGH_GRASP, PRECISE_GRASP, LIFT); where the
methods differ the states call the task's method object (method.py, ``Task.rules``). What only
one method keeps is not here: it is that method's ``State`` (its module), held as ``Task.ms``.
"""


from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

from mobigrasp.host import arm_calib, kinematics
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.fixedpoint import isqrt
from mobigrasp.host.kinematics import PAPER_000, PAPER_002, ArmGeometry
from mobigrasp.host.posture import PostureParams, adjust_posture
from mobigrasp.host.task.adjust import ADJUST
from mobigrasp.host.task.approach import PATH
from mobigrasp.host.task.grasp import GRASP
from mobigrasp.host.task.method import Method, MethodState, method_rules
from mobigrasp.host.task.params import TaskParams
from mobigrasp.host.task.search import SEARCH
from mobigrasp.host.task.sense import (
    odom_to_platform_q4,
    platform_to_odom_mm,
    plus_positions,
)
from mobigrasp.protocol.frozen import built

STATES = ("SEARCH", "APPROACH", "ADJUST", "ROUGH_GRASP", "PRECISE_GRASP", "LIFT", "DONE",
          "LOST", "FAILED")
TERMINAL = ("DONE", "FAILED")
HOME_ARM = (0, 0, -1571, -1571, 1571, 0)  # gripper open, roll 0, camera looking down
# each state's entry action (task, now_us, inputs) and step (task, now_us, inputs, detections);
# the terminal states have neither
ENTRY = {"SEARCH": SEARCH.enter_SEARCH, "APPROACH": PATH.enter_APPROACH,
         "ADJUST": ADJUST.enter_ADJUST, "ROUGH_GRASP": GRASP.enter_ROUGH_GRASP,
         "PRECISE_GRASP": GRASP.enter_PRECISE_GRASP, "LIFT": GRASP.enter_LIFT,
         "LOST": SEARCH.enter_LOST}
STEP = {"SEARCH": SEARCH.do_SEARCH, "APPROACH": PATH.do_APPROACH, "ADJUST": ADJUST.do_ADJUST,
        "ROUGH_GRASP": GRASP.do_ROUGH_GRASP, "PRECISE_GRASP": GRASP.do_PRECISE_GRASP,
        "LIFT": GRASP.do_LIFT, "LOST": SEARCH.do_LOST}


@dataclass(frozen=True)
class TaskInputs:
    """What the host knows at one control step (see the module docstring)."""

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
        return built(cls, joints_mrad=joints_mrad, x_mm=x_mm, y_mm=y_mm,
                     heading_mrad=heading_mrad, v_mmps=v_mmps, sonar_mm=sonar_mm,
                     detections=detections, grasp_closed=grasp_closed)


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


class Task:
    """The move-to-grasp state machine for one method ("000", "001" or "002"): ``rules`` is
    the method's object (host/task/method.py), chosen once by name."""

    def __init__(self, method: str, params: dict | None = None,
                 link_lengths_mm: tuple | None = None, start_us: int = 0) -> None:
        self.rules: Method = method_rules(method)  # ValueError naming the methods if unknown
        self.method = method
        self.p = TaskParams.for_method(method, params)
        if link_lengths_mm is None:
            link_lengths_mm = self.rules.link_lengths_mm
        if len(link_lengths_mm) != 3 or min(link_lengths_mm) <= 0:
            raise ValueError(f"link_lengths_mm must be three positive lengths, "
                             f"got {link_lengths_mm!r}")
        self.geom: ArmGeometry = ArmGeometry.from_mm(*link_lengths_mm)
        if tuple(link_lengths_mm) == (95.5, 89.0, 97.0):
            self.geom = PAPER_000
        elif tuple(link_lengths_mm) == (97.0, 89.0, 95.5):
            self.geom = PAPER_002
        self.cam = self.rules.camera
        self.state = "SEARCH"
        self.entered_us = int(start_us)
        self.counters = {"bad_inputs": 0, "bad_detections": 0, "lost": 0, "plans": 0}
        self._events: list[TaskEvent] = []
        self._detail: dict = {}
        self._ops = OpCounts()
        self._init_state(int(start_us))

    def _init_state(self, now_us: int) -> None:
        """The state the states share, at the start (the arm at HOME_ARM, nothing seen), and
        the method's own (``ms``, a fresh ``rules.State``)."""
        self.arm = list(HOME_ARM)
        self.joints = tuple(HOME_ARM)
        self.gripper = 0
        self.wheels = (0, 0)
        self.entry_pending = True
        self.failure = None
        self.search = None
        self.turn_from = None
        self.wander_from = None
        self.wander_round = None  # SEARCH: the drive round an obstacle that stopped a leg
        self.wander_look = None  # SEARCH: the heading to face to look after a stopped leg
        self.obj = None  # odometry-frame (x_mm, y_mm) of the object
        self.obj_seen_us = now_us
        self.follower = None
        self.plan_job = None  # a plan charged in slices (host/planning/anytime.py)
        self.plan_obj = None
        self.plan_us = now_us
        self.plan_attempts = 0
        self.move_done_us = now_us
        self.phase = ""
        self.phase_us = now_us
        self.precise_steps = 0
        self.lost_in = None  # the state the object was lost in, for the next SEARCH
        self.close_by = None  # PRECISE_GRASP: what decided the close (grasp.py descend)
        self.last_pose = (0, 0, 0, 0)
        self.arm_hist: list = []
        self.pose_hist: list = []
        self.confirm_until = None
        self.confirm_failed = None
        self.sighting = None  # odometry place of the last unconfirmed sighting (000/001)
        self.far = None  # SEARCH: the drive to a far sighting under way (search.py far_step)
        self.far_count = 0  # ... drives to far sightings made in the run
        self.guard_out = None  # 000, 002: the drive out of R_r after a guard stop (sonar_guard.py)
        self.side_echoes: list = []  # the close guard's remembered echo edges (sonar_guard.py)
        self.sonar_last: tuple = ()  # ... the ring's readings of the step before
        self.sight_frames = 0  # ROUGH_GRASP: dual "+" sightings of its look (grasp.py)
        self.sight_look = 0  # ... the index of its look (waist offset, wrist roll)
        self.sight_th5 = 0  # ... the waist of its view, the looks' offsets are added to
        self.sight_adjusts = 0  # ... that sent the base back to ADJUST for this grasp
        self.reach_mm: tuple[int, int] | None = None  # ROUGH_GRASP: the grasp reach to drive to
        self.regrasps = 0  # LIFT: grasps found to have missed by the grasp check (grasp.py)
        self.held_tips: dict = {}  # LIFT: fingertip places the object was seen under (grasp.py)
        # the object itself (not a guide board) has been seen, or its place P_i given (001 §II)
        self.graspable_seen = bool(self.p.object_xy_mm)
        # ... by the camera (the check by absence needs it); dropped by a blind grasp that found
        # no evidence of it (grasp.py)
        self.object_sighted = False
        self._pp_of, self._pp_by_cap = None, {}  # posture parameters built for TaskParams _pp_of
        self.trust_from_us = 0
        self.plus_odom = None
        self.grasp_xy_q4 = None
        self.grasp_alpha = self.rules.grasp_alpha_mrad
        self.roll_scan = 0  # PRECISE_GRASP: wrist-roll steps of its spoke search (grasp.py)
        self.check_seen = 0  # LIFT: frames in which the grasp check saw the object held
        self.check_waist = None  # ... its look's (centre waist, index into the offsets)
        self.ms: MethodState = self.rules.State()  # what only the method keeps (its module)

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
        reason = self.rules.failure_reason(self, reason)
        self.failure = reason
        self.go(now_us, "FAILED", reason)

    def note(self, **kw: Any) -> None:
        """Add to this step's trace detail."""
        self._detail.update(kw)

    def charge(self, ops: OpCounts) -> None:
        """Add modelled ARM9 work done in this step (planning)."""
        self._ops = self._ops + ops

    def detectors_needed(self) -> list[str]:
        """The detectors the current state uses (so the host runs and pays for only these);
        SEARCH's on every frame, while the base turns too (a target passing through the view
        during a turn is seen, docs/task.md)."""
        return list(self.rules.detectors.get(self.state, ()))

    def detector_fallbacks(self) -> dict[str, str]:
        """Detectors of :meth:`detectors_needed` that stand in for another on the same frame:
        name -> the detector listed before it, whose result makes it unnecessary (the host runs
        it only when that one found nothing)."""
        return dict(self.rules.detector_fallbacks.get(self.state, {}))

    # --- shared by the states: arm targets, history, object estimate -------------------------
    def set_arm(self, now: int, th2: int, th3: int, th4: int, th5: int,
                th1: int | None = None) -> None:
        """New arm targets (clamped) and the time by which the servos will have got there."""
        new = list(self.arm)
        if th1 is not None:
            new[1] = th1
        new[2:6] = [th2, th3, th4, th5]
        new = list(arm_calib.clamp_joints_mrad(new))
        travel = max(abs(a - b) for a, b in zip(new[1:], self.arm[1:], strict=True))
        self.arm = new
        done = now + travel * 1_000_000 // self.p.servo_speed_mrad_per_s + self.p.settle_margin_us
        self.move_done_us = max(self.move_done_us if travel == 0 else now, done)

    def settled(self, now: int) -> bool:
        return now >= self.move_done_us

    def remember(self, now: int, inp) -> None:
        """Keep the last second of arm targets and base poses: a detection describes the frame
        captured ``frame_latency_us`` ago (capture + vision), not the arm and base of now."""
        if not self.arm_hist or self.arm_hist[-1][1] != tuple(self.arm):
            self.arm_hist.append((now, tuple(self.arm)))
        self.pose_hist.append((now, inp.x_mm, inp.y_mm, inp.heading_mrad))
        for hist in (self.arm_hist, self.pose_hist):
            while len(hist) > 1 and hist[1][0] <= now - 1_000_000:
                hist.pop(0)

    @staticmethod
    def _at(hist: list, t_us: int):
        best = hist[0]
        for item in hist:
            if item[0] <= t_us:
                best = item
        return best

    def arm_at(self, t_us: int) -> tuple[int, ...]:
        """The arm targets at ``t_us`` (the last second is kept); the present ones without a
        history."""
        return self._at(self.arm_hist, t_us)[1] if self.arm_hist else tuple(self.arm)

    def pose_at(self, t_us: int) -> tuple[int, int, int, int]:
        """(t_us, x_mm, y_mm, heading_mrad) of the base at ``t_us`` (needs a history)."""
        return self._at(self.pose_hist, t_us)

    def see_object(self, now: int, inp, name: str, det) -> bool:
        """Update the object estimate from a detection; False if unusable (counted)."""
        t_cap = now - self.p.frame_latency_us
        if t_cap < self.trust_from_us:
            return False  # captured while the arm swung to a new posture: pose unknown
        joints = self.arm_at(t_cap)
        _, x, y, h = self._at(self.pose_hist, t_cap) if self.pose_hist else (
            0, inp.x_mm, inp.y_mm, inp.heading_mrad)
        try:
            p = self.rules.object_position(self, name, det, joints)
        except (ValueError, TypeError, ZeroDivisionError):
            self.counters["bad_detections"] += 1
            return False
        if p is None or isqrt(p[0] * p[0] + p[1] * p[1]) > 5000 * 16:
            self.counters["bad_detections"] += 1
            return False
        self.obj = platform_to_odom_mm(x, y, h, self.p.mount_forward_mm, p)
        self.obj_seen_us = now
        if name in self.rules.object_detectors:
            self.graspable_seen = self.object_sighted = True
        if name == "dual_plus":
            self._remember_plus(det, joints, (x, y, h))
        return True

    def _remember_plus(self, det, joints: tuple, pose: tuple) -> None:
        """Keep both "+" in the odometry frame: the precise grasp looks at one of them (000:
        "only a '+' symbol is used in the precise grasping")."""
        try:
            top = ((self.p.object_top_mm - self.p.h_shoulder_mm) * 16
                   if self.rules.plus_on_top else None)
            pair = plus_positions(det, self.geom, joints, self.cam, top)
        except (ValueError, TypeError, ZeroDivisionError):
            return
        if pair is None:
            return
        (ax, ay, _), (bx, by, _) = pair
        if not 30 * 16 <= isqrt((ax - bx) ** 2 + (ay - by) ** 2) <= 65 * 16:
            return  # not 47.3 mm apart: a bad pair
        self.plus_odom = tuple(platform_to_odom_mm(*pose, self.p.mount_forward_mm, q)
                               for q in pair)

    def obj_platform(self, inp) -> tuple[int, int]:
        return odom_to_platform_q4(inp.x_mm, inp.y_mm, inp.heading_mrad,
                                   self.p.mount_forward_mm, self.obj[0], self.obj[1])

    def look_at_object(self, inp, top: bool = True) -> None:
        """Posture adjustment (eq. (10) of 000) toward the estimated object."""
        if self.obj is None:
            return
        x, y = self.obj_platform(inp)
        look_mm = self.rules.look_height_mm(self.p, top)
        z = (look_mm - self.p.h_shoulder_mm) * 16
        adj = adjust_posture(self.geom, tuple(self.arm[2:6]), (x, y, z), self.posture_params())
        self.arm[2:6] = [adj.theta2_mrad, adj.theta3_mrad, adj.theta4_mrad, adj.theta5_mrad]

    def posture_params(self, max_step_mrad: int | None = None) -> PostureParams:
        """The task's posture parameters (``self.p.posture`` with the step cap, by default
        ``posture_step_mrad``); built once per TaskParams and cap, not at every control step."""
        cap = self.p.posture_step_mrad if max_step_mrad is None else max_step_mrad
        if self._pp_of is not self.p:  # first call, or new TaskParams
            self._pp_of, self._pp_by_cap = self.p, {}
        pp = self._pp_by_cap.get(cap)
        if pp is None:
            pp = self._pp_by_cap[cap] = PostureParams(**{"max_step_mrad": cap,
                                                         **self.p.posture})
        return pp

    def gripper_point_q4(self) -> tuple[int, int, int]:
        return kinematics.fk_mm_q4(self.geom, *self.arm[2:6])

    def grasp_ik(self, target_q4: tuple[int, int, int], alpha: int | None = None):
        """IK at the pitch ``alpha``, or the method's grasp pose (``Method.grasp_ik``)."""
        if alpha is not None:
            return kinematics.ik_pitch_mm_q4(self.geom, target_q4, alpha)
        return self.rules.grasp_ik(self.geom, target_q4)

    def apply_pose(self, now: int, pose, th1: int | None = None) -> None:
        self.set_arm(now, pose.theta2_mrad, pose.theta3_mrad, pose.theta4_mrad,
                     pose.theta5_mrad, th1)

    def _run_state(self, now: int, inp: TaskInputs, dets: dict) -> None:
        """The state's entry action once after a transition, then its step."""
        if self.entry_pending:
            self.entry_pending = False
            state = self.state
            ENTRY[state](self, now, inp)
            if self.state != state:
                return
        STEP[self.state](self, now, inp, dets)

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
            self._run_state(now_us, inp, dets)
            self.rules.guard_wheels(self, now_us, inp)
            self.remember(now_us, inp)
        if self.state in TERMINAL:
            self.wheels = (0, 0)
        servo = arm_calib.clamp_joints_mrad((self.gripper,) + tuple(self.arm[1:]))
        return TaskOutputs(servo, self.wheels, self.gripper, list(self._events), self.state,
                           dict(self._detail), self._ops)
