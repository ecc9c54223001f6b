"""What differs between the papers' methods, behind one interface the state machine calls.

The machine (host/task/machine.py) and the state groups (search.py, approach.py, adjust.py,
grasp.py) are the same for every method; where 000, 001 and 002 differ they ask the task's
:class:`Method` object (``task.rules``), chosen once by name from :data:`METHODS`. Each
method's module holds its part: method000.py (radial symbol, dual "+", spoke, Bezier paths of
eq. (9), the gripper down), method001.py (000's vision with 001's sonar replanning of eq. (17)
and §III.E), method002.py (double cross, fuzzy approach, red cylinder, the level gripper of
eq. (4)).

A method is one module and one row. The module holds the method's class and ``RULES``, its
instance: its parameters as its paper names them (:class:`Param` rows of ``paper_params``, the
scenario's ``[params]``, and how they map onto the task's parameters, ``paper_to_task``), its own
state (``State``, a dataclass the task holds as ``t.ms``: what only this method keeps between
steps) and its rules (the hooks below). The row is its name and module in :data:`METHODS`;
everything that lists methods reads that table through :data:`REGISTRY`: the task, the scenario
loader (which receives it: mcu_sim never imports the host), the CLI, campaigns and the random
scene generator (docs/architecture.md "Adding a method").

A hook takes the task ``t`` first and reads and sets the task's state through it: the state the
states share on the task, the method's own in ``t.ms``.
"""

from __future__ import annotations

import importlib
import math
from abc import ABC, abstractmethod
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

from mobigrasp.host.task.sense import CameraModel, object_in_platform
from mobigrasp.host.task.sonar_guard import SONAR_GUARD
from mobigrasp.host.vision import registry
from mobigrasp.host.vision.held_fill import OBJECT_COLOURS

if TYPE_CHECKING:
    from mobigrasp.host.task.machine import Task


class Param(NamedTuple):
    """A paper parameter: type (int: must be an integer; float accepts int or float), the
    paper's value, the physical range [lo, hi] it is accepted in, and its unit/meaning."""

    kind: type
    default: float
    lo: float
    hi: float
    unit: str


PI = math.pi
K_THETA = "k_theta"  # paper_to_task group: index into PostureParams.k_theta_q12


def mrad(x: float) -> int:
    """To the host's integer thousandths: rad -> mrad, m -> mm, m/s -> mm/s."""
    return int(round(1000 * x))


def q12(x: float) -> int:
    """A gain to Q12."""
    return int(round(4096 * x))


@dataclass(frozen=True)
class SceneHints:
    """What the random scenes (services/random_scenarios.py) put before the method."""

    target_kind: str  # the target of its paper (mcu_sim/world/scenario.py TARGET_KINDS)
    time_limit_s: float
    obstacles: bool = False  # obstacles between the robot and a far target (001's sonars)
    guide_board: bool = False  # a guidance board facing the start, some scenes it alone (002)
    moving_target: bool = False  # the target dragged during the approach (002 Fig. 4)


@dataclass
class MethodState:
    """A method's own state between steps (``t.ms``); a method with none keeps this."""


class Method(ABC):
    """One paper's method: its parameters, its state's type, its constants and the hooks of
    the states where it differs."""

    name: str
    # the scenario's [params]: the paper's names, values (the paper's own) and ranges
    paper_params: Mapping[str, Param]
    # paper parameters nothing in the run reads (constants of a detector, a marker or the
    # plant): the scenario loader refuses them, so that every [params] key in a file is in force
    not_used_params: tuple[str, ...] = ()
    # (lo, hi, gap): pairs the loader keeps ordered, hi - lo >= gap
    param_order: tuple[tuple[str, str, float], ...] = ()
    # paper name -> (TaskParams table, field, conversion to the host's unit; table None: a
    # TaskParams field of its own; K_THETA: an index into the posture gains); names not listed
    # are read by the world or refused by the loader (not_used_params)
    paper_to_task: Mapping[str, tuple[Any, Any, Any]] = {}
    scene: SceneHints
    # the robot the world builds for a scenario of this method (its arm, grasp pitch and sonar
    # ring: mcu_sim/world/arm.py ARM_BY_METHOD, keyed by the paper that built the robot)
    robot: str
    object_given: bool = False  # the task is given the object's place P_i (001 §II)
    State: type[MethodState] = MethodState
    link_lengths_mm: tuple[float, float, float]  # l2, l3, l4 of the arm the method assumes
    camera: CameraModel
    param_defaults: dict  # TaskParams fields whose defaults differ for this method
    detectors: dict[str, tuple[str, ...]]  # state -> detectors it runs (host/vision/registry)
    # state -> {detector: the one listed before it whose miss on the same frame it stands in
    # for}: the host runs it only when that one found nothing (docs/budget.md, "ADJUST")
    detector_fallbacks: Mapping[str, Mapping[str, str]] = {}
    search_detector: str  # what SEARCH looks for
    adjust_detector: str  # what ADJUST closes in on
    check_detectors: tuple[str, ...]  # what the grasp check of LIFT looks for
    # the object's colour that fills the hand camera's frame while it is held (a key of
    # host/vision/held_fill.py OBJECT_COLOURS; the grasp check's evidence, held_in_view)
    held_colour: str
    plus_on_top: bool = False  # the two "+" placed where their rays meet the top (sense.py)
    # ADJUST starts from the posture it enters with and moves the joints by eq. (10) of 000
    # alone (True), or first puts the elbow and shoulder to the close-look posture
    # (``adjust_theta3_mrad``, ``adjust_theta4_mrad``; host/task/adjust.py)
    adjust_keeps_posture: bool = False
    # ROUGH_GRASP first looks at the object from these (range mm, pitch down mrad), the first
    # the arm reaches, the base standing still, and grasps on that sighting (grasp.py); ():
    # the grasp goes on the estimate ADJUST ended with
    sight_views: tuple[tuple[int, int], ...] = ()
    object_detectors: tuple[str, ...]  # detectors that see the object itself (not a guide)
    grasp_alpha_mrad: int  # gripper pitch of the grasp before the rough grasp chooses one
    keeps_sightings: bool  # SEARCH: an unconfirmed sighting seen again at its place counts

    # --- SEARCH --------------------------------------------------------------------------------
    @abstractmethod
    def found(self, t: Task, now: int, inp: Any, name: str, det: Any) -> bool:
        """The search detector's result ``det`` gives a usable object or bearing (kept)."""

    @abstractmethod
    def found_why(self, t: Task) -> str:
        """The transition's reason once the search has found the object."""

    def lost_search(self, t: Task, sp: Any, lost_in: str) -> tuple[Any, int, int] | None:
        """SEARCH after the object was lost in state ``lost_in`` near it: the search's
        parameters ``sp`` (host.search.SearchParams) as changed, and its start (theta2s,
        theta5s mrad); None: the usual search from the arm's joints."""
        return None

    def search_back_off(self, t: Task, now: int, inp: Any, dets: dict) -> bool:
        """SEARCH's step taken by a back-off from an object too near to be seen whole (True:
        the step is done); False: the search goes on."""
        return False

    def search_cut_look(self, t: Task, now: int) -> int | None:
        """A wander leg stopped short by an obstacle ahead: the odometry heading (mrad) to face
        when the method has seen the object too near to be read whole lately (it may be what
        stopped the leg), for the search to look around there before the next station; None:
        the next station."""
        return None

    def grasp_lost(self, t: Task, now: int, waited_us: int) -> bool:
        """PRECISE_GRASP saw no spoke for ``waited_us`` over the roll scan: True when the method
        searches for the object instead (the transition made), False to go down on the rough
        position."""
        return False

    # --- APPROACH ------------------------------------------------------------------------------
    @abstractmethod
    def enter_approach(self, t: Task, now: int, inp: Any) -> None:
        """Entry action of APPROACH, after the common reset of the path follower."""

    @abstractmethod
    def approach(self, t: Task, now: int, inp: Any, dets: dict) -> None:
        """One step of APPROACH."""

    # --- ADJUST --------------------------------------------------------------------------------
    @abstractmethod
    def adjust_done(self, t: Task, now: int, det: Any, dist_mm: int) -> bool:
        """ADJUST ends on this frame's ``det`` of the adjust detector (the transition made)."""

    @abstractmethod
    def adjust_vmax_mmps(self, p: Any) -> int:
        """Speed limit of the close approach in ADJUST."""

    # --- the arm -------------------------------------------------------------------------------
    @abstractmethod
    def look_height_mm(self, p: Any, top: bool) -> int:
        """Height above the ground the posture adjustment keeps in view (``top``: the
        object's marker; else the grasp height)."""

    @abstractmethod
    def grasp_ik(self, geom: Any, target_q4: tuple[int, int, int]) -> Any:
        """The method's grasp pose for a platform-frame target (ArmPose or Unreachable)."""

    @abstractmethod
    def rough_target(self, t: Task, inp: Any) -> tuple[int, int, int]:
        """ROUGH_GRASP: where the gripper goes first (platform frame, Q4 mm)."""

    @abstractmethod
    def lowers_hover(self) -> bool:
        """ROUGH_GRASP: an unreachable target may be tried lower (the hover height)."""

    @abstractmethod
    def enter_precise(self, t: Task, now: int, inp: Any) -> None:
        """Entry action of PRECISE_GRASP (after the step counter and phase clock reset)."""

    # --- after every step ---------------------------------------------------------------------
    def guard_wheels(self, t: Task, now: int, inp: Any) -> None:
        """Last-line check of the step's wheel speeds: the sonar guard (stop below R_r, turn
        to the widest free sector, drive out; host/task/sonar_guard.py)."""
        SONAR_GUARD.step(t, now, inp)

    # --- hooks with a common default -----------------------------------------------------------
    def search_sighting(self, dets: dict) -> tuple[str, Any]:
        """SEARCH: the detector whose result of this frame is looked at, and the result."""
        return self.search_detector, dets.get(self.search_detector)

    def search_gives_up(self, t: Task) -> str | None:
        """SEARCH ends FAILED with this reason (None: it goes on, as long as its timeout)."""
        return None

    def object_position(self, t: Task, name: str, det: Any, joints: tuple[int, ...]) -> Any:
        """The object's platform-frame position (Q4 mm) from detector ``name``'s result seen
        with the arm at ``joints``: the detector's pinhole sighting (host/task/sense.py)."""
        return object_in_platform(name, det, t.geom, joints, t.cam)

    def adjust_goal_mm(self, t: Task) -> tuple[int, int]:
        """ADJUST's close approach stops the object this far ahead of the waist, +- tol."""
        return t.p.grasp_r_mm, t.p.grasp_r_tol_mm

    def grasp_reach_mm(self, t: Any) -> tuple[int, int] | None:
        """ROUGH_GRASP: the object's distance from the waist (mm, centre and tolerance) the
        grasp pose needs; the base drives there first when the object is outside. None: the
        grasp goes from where ADJUST stopped."""
        return None

    def look_decides(self, t: Any, now: int, inp: Any) -> bool:
        """ROUGH_GRASP after its look (``sight_views``): True when the method has decided what
        follows (the transition or the grasp pose made); False: the common rule (grasp.py)."""
        return False

    def held_view_pose(self, t: Any) -> Any:
        """LIFT: the arm pose of the grasp check's look; None: the common look, the camera
        straight above the fingertip looking down (host/task/grasp.py)."""
        return None

    def held_in_view(self, t: Task, now: int, dets: dict) -> bool:
        """LIFT: this frame shows the object held (grasp evidence at the present waist
        offset): the frame is filled by the object's own colour, the camera at the fingertip
        being inside the object between the fingers (docs/task.md). Frames of a swing (the
        arm's pose unknown) are not evidence."""
        fill = dets.get("held_fill")
        if not isinstance(fill, registry.row("held_fill").result_type()) \
                or now - t.p.frame_latency_us < t.trust_from_us:
            return False
        held = OBJECT_COLOURS[self.held_colour](fill.rgb)
        t.note(grasp_check_fill={"rgb": list(fill.rgb), "permille": fill.fill_permille,
                                 "held": held})
        return held

    def object_cue_seen(self, t: Any) -> bool:
        """A cue of the object itself (002: the red cylinder's colour ROI), not of a guide,
        was seen although the object's own detector never measured it: ROUGH_GRASP without a
        sighting of the object then searches again (LOST) rather than failing the run."""
        return False

    def failure_reason(self, t: Task, reason: str) -> str:
        """The reason FAILED gives (a method may say more)."""
        return reason


# The registry: method name -> the module holding its ``RULES`` (one row per method).
METHODS = {"000": "mobigrasp.host.task.method000", "001": "mobigrasp.host.task.method001",
           "002": "mobigrasp.host.task.method002"}


def method_rules(name: str) -> Method:
    """The method object of ``name`` (its module's ``RULES``); unknown name -> ValueError
    naming the known ones."""
    module = METHODS.get(name) if isinstance(name, str) else None
    if module is None:
        raise ValueError(f"method must be one of {tuple(METHODS)}, got {name!r}")
    return importlib.import_module(module).RULES


class MethodTable(Mapping[str, Method]):
    """The registry as a read-only mapping name -> method object, the rows as they are now
    (a row added later is in it); a method's module is imported when it is first asked for."""

    def __getitem__(self, name: str) -> Method:
        if name not in METHODS:
            raise KeyError(name)
        return method_rules(name)

    def __iter__(self) -> Iterator[str]:
        return iter(tuple(METHODS))

    def __len__(self) -> int:
        return len(METHODS)

    def __contains__(self, name: object) -> bool:
        return name in METHODS


REGISTRY = MethodTable()
