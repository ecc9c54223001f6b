"""A toy method for the registry test: it creeps straight ahead, whatever the state.

It is what a new method module provides (docs/architecture.md, "Adding a method"): its paper
parameters (``paper_params``) and their mapping onto the task's (``paper_to_task``), its own
state (``State``, a dataclass), its scene for the random generator, the robot the world builds
for it, and the hooks of the states (host/task/method.py). Registered from the test as one row
of ``METHODS``; nothing else in the project names it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from mobigrasp.host import kinematics
from mobigrasp.host.task.method import Method, MethodState, Param, SceneHints, mrad
from mobigrasp.host.task.sense import CameraModel

CREEP_MPS = 0.1  # the toy paper's creeping speed


@dataclass
class ToyState(MethodState):
    """What the toy keeps: the steps it has driven, and the speed of the last one."""

    steps: int = 0
    last_mmps: int = 0


class ToyMethod(Method):
    """Creeps ahead at ``creep_mps`` after every step (its ``guard_wheels``); finds nothing."""

    name = "toy"
    paper_params = {"creep_mps": Param(float, CREEP_MPS, 0.0, 0.3, "m/s, creeping speed"),
                    "shade": Param(int, 3, 0, 9, "the toy paper's colour, read by nothing")}
    not_used_params = ("shade",)
    paper_to_task = {"creep_mps": ("planner", "creep_mmps", mrad)}  # m/s -> mm/s
    scene = SceneHints("radial-symbol", 60.0)
    robot = "000"
    State = ToyState
    link_lengths_mm = (95.5, 89.0, 97.0)
    camera = CameraModel(500, 160, 120)
    param_defaults: dict = {}
    detectors: dict = {}  # looks at nothing: no vision is run or charged
    search_detector = adjust_detector = "radial_symbol"
    check_detectors = object_detectors = ()
    held_colour = "body_brown"  # never reaches the grasp check
    grasp_alpha_mrad = kinematics.ALPHA_DOWN_MRAD
    keeps_sightings = False

    def guard_wheels(self, t: Any, now: int, inp: Any) -> None:
        v = t.p.planner.get("creep_mmps", mrad(CREEP_MPS))
        t.wheels = (v, v)
        t.ms.steps += 1
        t.ms.last_mmps = v

    def found(self, t: Any, now: int, inp: Any, name: str, det: Any) -> bool:
        return False

    def found_why(self, t: Any) -> str:
        return "never"

    def enter_approach(self, t: Any, now: int, inp: Any) -> None:
        pass

    def approach(self, t: Any, now: int, inp: Any, dets: dict) -> None:
        pass

    def adjust_done(self, t: Any, now: int, det: Any, dist_mm: int) -> bool:
        return False

    def adjust_vmax_mmps(self, p: Any) -> int:
        return p.adjust_vmax_mmps

    def look_height_mm(self, p: Any, top: bool) -> int:
        return p.object_top_mm

    def grasp_ik(self, geom: Any, target_q4: tuple[int, int, int]) -> Any:
        return kinematics.ik_rough_grasp_000(geom, target_q4)

    def rough_target(self, t: Any, inp: Any) -> tuple[int, int, int]:
        return (0, 0, 0)

    def lowers_hover(self) -> bool:
        return False

    def enter_precise(self, t: Any, now: int, inp: Any) -> None:
        pass


RULES = ToyMethod()
