"""What differs between the papers' methods, behind one interface the state machine calls.

The machine (host/task/machine.py) and the state groups (search.py, approach.py, adjust.py,
grasp.py) are the same for every method; where 000, 001 and 002 differ they ask the task's
:class:`Method` object (``task.rules``), chosen once by name from :data:`METHODS`. Each
method's module holds its part: method000.py (radial symbol, dual "+", spoke, Bezier paths of
eq. (9), the gripper down), method001.py (000's vision with 001's sonar replanning of eq. (17)
and §III.E), method002.py (double cross, fuzzy approach, red cylinder, the level gripper of
eq. (4)).

A hook takes the task ``t`` first and reads and sets the task's state through it.
"""

from __future__ import annotations

import importlib
from abc import ABC, abstractmethod
from typing import Any

from mobigrasp.host.task.sense import CameraModel, object_in_platform
from mobigrasp.host.task.sonar_guard import SONAR_GUARD
from mobigrasp.host.vision import registry
from mobigrasp.host.vision.held_fill import OBJECT_COLOURS


class Method(ABC):
    """One paper's method: its constants and the hooks of the states where it differs."""

    name: str
    link_lengths_mm: tuple[float, float, float]  # l2, l3, l4 of the arm the method assumes
    camera: CameraModel
    param_defaults: dict  # TaskParams fields whose defaults differ for this method
    detectors: dict[str, tuple[str, ...]]  # state -> detectors it runs (host/vision/registry)
    search_detector: str  # what SEARCH looks for
    adjust_detector: str  # what ADJUST closes in on
    check_detectors: tuple[str, ...]  # what the grasp check of LIFT looks for
    # the object's colour that fills the hand camera's frame while it is held (a key of
    # host/vision/held_fill.py OBJECT_COLOURS; the grasp check's evidence, held_in_view)
    held_colour: str
    plus_on_top: bool = False  # the two "+" placed where their rays meet the top (sense.py)
    # ROUGH_GRASP first looks at the object from these (range mm, pitch down mrad), the first
    # the arm reaches, the base standing still, and grasps on that sighting (grasp.py); ():
    # the grasp goes on the estimate ADJUST ended with
    sight_views: tuple[tuple[int, int], ...] = ()
    object_detectors: tuple[str, ...]  # detectors that see the object itself (not a guide)
    grasp_alpha_mrad: int  # gripper pitch of the grasp before the rough grasp chooses one
    keeps_sightings: bool  # SEARCH: an unconfirmed sighting seen again at its place counts

    # --- SEARCH --------------------------------------------------------------------------------
    @abstractmethod
    def found(self, t: Any, now: int, inp: Any, name: str, det: Any) -> bool:
        """The search detector's result ``det`` gives a usable object or bearing (kept)."""

    @abstractmethod
    def found_why(self, t: Any) -> str:
        """The transition's reason once the search has found the object."""

    def lost_search(self, t: Any, sp: Any, lost_in: str) -> tuple[Any, int, int] | None:
        """SEARCH after the object was lost in state ``lost_in`` near it: the search's
        parameters ``sp`` (host.search.SearchParams) as changed, and its start (theta2s,
        theta5s mrad); None: the usual search from the arm's joints."""
        return None

    def grasp_lost(self, t: Any, now: int, waited_us: int) -> bool:
        """PRECISE_GRASP saw no spoke for ``waited_us`` over the roll scan: True when the method
        searches for the object instead (the transition made), False to go down on the rough
        position."""
        return False

    # --- APPROACH ------------------------------------------------------------------------------
    @abstractmethod
    def enter_approach(self, t: Any, now: int, inp: Any) -> None:
        """Entry action of APPROACH, after the common reset of the path follower."""

    @abstractmethod
    def approach(self, t: Any, now: int, inp: Any, dets: dict) -> None:
        """One step of APPROACH."""

    # --- ADJUST --------------------------------------------------------------------------------
    @abstractmethod
    def adjust_done(self, t: Any, now: int, det: Any, dist_mm: int) -> bool:
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
    def rough_target(self, t: Any, inp: Any) -> tuple[int, int, int]:
        """ROUGH_GRASP: where the gripper goes first (platform frame, Q4 mm)."""

    @abstractmethod
    def lowers_hover(self) -> bool:
        """ROUGH_GRASP: an unreachable target may be tried lower (the hover height)."""

    @abstractmethod
    def enter_precise(self, t: Any, now: int, inp: Any) -> None:
        """Entry action of PRECISE_GRASP (after the step counter and phase clock reset)."""

    # --- after every step ---------------------------------------------------------------------
    def guard_wheels(self, t: Any, now: int, inp: Any) -> None:
        """Last-line check of the step's wheel speeds: the sonar guard (stop below R_r, turn
        to the widest free sector, drive out; host/task/sonar_guard.py)."""
        SONAR_GUARD.step(t, now, inp)

    # --- hooks with a common default -----------------------------------------------------------
    def search_sighting(self, dets: dict) -> tuple[str, Any]:
        """SEARCH: the detector whose result of this frame is looked at, and the result."""
        return self.search_detector, dets.get(self.search_detector)

    def search_gives_up(self, t: Any) -> str | None:
        """SEARCH ends FAILED with this reason (None: it goes on, as long as its timeout)."""
        return None

    def object_position(self, t: Any, name: str, det: Any, joints: tuple[int, ...]) -> Any:
        """The object's platform-frame position (Q4 mm) from detector ``name``'s result seen
        with the arm at ``joints``: the detector's pinhole sighting (host/task/sense.py)."""
        return object_in_platform(name, det, t.geom, joints, t.cam)

    def adjust_goal_mm(self, t: Any) -> tuple[int, int]:
        """ADJUST's close approach stops the object this far ahead of the waist, +- tol."""
        return t.p.grasp_r_mm, t.p.grasp_r_tol_mm

    def grasp_reach_mm(self, t: Any) -> tuple[int, int] | None:
        """ROUGH_GRASP: the object's distance from the waist (mm, centre and tolerance) the
        grasp pose needs; the base drives there first when the object is outside. None: the
        grasp goes from where ADJUST stopped."""
        return None

    def held_view_pose(self, t: Any) -> Any:
        """LIFT: the arm pose of the grasp check's look; None: the common look, the camera
        straight above the fingertip looking down (host/task/grasp.py)."""
        return None

    def held_in_view(self, t: Any, now: int, dets: dict) -> bool:
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

    def failure_reason(self, t: Any, reason: str) -> str:
        """The reason FAILED gives (a method may say more)."""
        return reason


# Method name -> module holding its class ``RULES``.
METHODS = {"000": "mobigrasp.host.task.method000", "001": "mobigrasp.host.task.method001",
           "002": "mobigrasp.host.task.method002"}
_LOADED: dict[str, Method] = {}


def method_rules(name: str) -> Method:
    """The method object of ``name`` (one per name); unknown name -> ValueError naming it."""
    rules = _LOADED.get(name)
    if rules is None:
        if name not in METHODS:
            raise ValueError(f"method must be one of {tuple(METHODS)}, got {name!r}")
        rules = _LOADED[name] = importlib.import_module(METHODS[name]).RULES
    return rules
