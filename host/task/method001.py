"""Paper 001's method: 000's vision and grasp with 001's sonar planning and replanning.

The object position P_i may be given (001 §II, ``object_xy_mm``); APPROACH plans with eq. (17)
over the infeasible regions of the sonar ring (eqs. (15)-(16), host.planning.bezier001) through
host.planning.replan's Replanner, which checks the rest of the path against fresh sonar every
``replan_period_us`` (§III.E). Ours, not 001's: the first plan waits for one sonar sweep;
sightings taken while the base turns fast are not used; the follower never backs up; when no
curve is feasible and the object is too far for the close approach, the base drives aside (the
detour: toward the free direction nearest the object's bearing, ``detour_mm``, then plans
again). The curve is followed to its end on the grasp circle (eqs. (5)-(6)); there the camera
looks back at the object with the base still (ROUGH_GRASP's look, ``sight_views``) and, the
object seen where expected, the arm grasps by inverse kinematics (§III.E's last sentence; eq.
(11) of 000, gripper down) from where the base stands; the look not confirming it, 000's ADJUST
and precise grasp take over (docs/task.md "001's grasp").
Integer mm / us; no I/O and no clock.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from mobigrasp.host import kinematics
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.control import path_follow
from mobigrasp.host.fixedpoint import atan2_mrad, atan2_ops, isqrt, sin_ops
from mobigrasp.host.planning.anytime import PlanJob
from mobigrasp.host.planning.bezier001 import Params001, is_object_echo
from mobigrasp.host.planning.bezier_q import DIV64_OPS, ISQRT64_OPS
from mobigrasp.host.planning.escape import escape_heading, segment_clear
from mobigrasp.host.planning.grasp_circle import ArmGeometry001, grasp_radius
from mobigrasp.host.planning.replan import Replanner
from mobigrasp.host.planning.sonar_regions import SonarConfig, infeasible_regions
from mobigrasp.host.search import SearchParams
from mobigrasp.host.task.drive import path_follower, state_m, turn_in_place, wrap_mrad
from mobigrasp.host.task.grasp import GRASP
from mobigrasp.host.task.method import Method, MethodState, Param, SceneHints, mrad
from mobigrasp.host.task.method000 import Method000
from mobigrasp.host.task.sonar_guard import (
    GUARDED_STATES,
    close_guard,
    drive_detour,
    free_heading_nearest,
    guard_stop,
    out_of_r_r,
    widest_free_heading,
)

if TYPE_CHECKING:
    from mobigrasp.host.control.path_follow import PathFollower, WheelCommand
    from mobigrasp.host.planning.replan import ReplanDecision
    from mobigrasp.host.task.machine import Task, TaskInputs
    from mobigrasp.host.task.params import TaskParams

ARC_BOUND_001 = True  # eq. (16) wedges cut to the grown echo arc (planner_params_001)
DETOUR_EXTRA_MM = 100  # a detour's way out is checked this much beyond its end (stopping)
DETOUR_MARGIN_MM = 100  # ... against the infeasible regions grown by this: it drives open-loop
SIGHTING_MAX_TURN_MRAD_S = 500  # APPROACH: sightings taken while turning faster are not used
# the grasp from the grasp circle: the look before it must see the object (dual "+") within
# this of the estimate the base arrived with; the gripper goes down from this far above the
# grasp point (the first reachable, in 10 mm steps down to the object's top)
CIRCLE_CONFIRM_MM = 60
CIRCLE_PRE_MM = 50
LOOK_FIRST_US = 4_000_000  # P_i given, object near and unseen: look this long first
LOOK_FIRST_MM = (350, 1200)  # ... when it is this far from the waist
BACK_OFF_MM = 200  # fallback: back this far along the way the base came
# SEARCH: the radial symbol cut by the frame's border (Method000.search_back_off) is nearer
# than its near limit: the base faces away from it, drives CUT_AWAY_MM off it, the sonars
# watching, and turns back to look; at most BACK_OFFS_001 a run (docs/task.md, "001: away
# from a symbol cut by the frame")
CUT_AWAY_MM = 400
BACK_OFFS_001 = 2
# ... once the symbol has been seen cut in frames CUT_WAIT_US apart, within CUT_STALE_US (the
# search's sweep brings a symbol in range whole into the frame within a second of its first
# cut frame, and reads it; a look-around takes ~30 s)
CUT_WAIT_US = 2_000_000
CUT_STALE_US = 30_000_000
# ... and with no cut frame: the object never seen by the camera, its estimate within this of
# the axle (the symbol's near limit, 0.45 m ahead of the camera, and the camera ~0.1 m ahead of
# the axle), once the search has looked all round here (``turns_per_wander`` cycles): the same
# move off the estimate instead of the wander's first leg (docs/task.md, "001: away from an
# estimate too near to be read")
UNSEEN_NEAR_MM = 550
# the fallback steps with no feasible curve (Method001.start_detour), the last one repeated
FALLBACKS = ("lower_v0", "back_off", "widest_sector", "detour")


# APPROACH's step along the curve (approach.py ``_follow``), charged each step as the plans'
# counts are (docs/budget.md "The control step's charge", 001): the look at the object (its
# platform place; eq. (10) of 000: the camera by fk, |ρ|, two atan2 with their 64-bit
# quotients, eq. (10)'s three quotients, two wraps, the caps and clamps), the distance checks
# (two 64-bit roots) and the follower's step (eq. (8), path_follow.STEP_OPS)
LOOK_OPS = (sin_ops().scaled(8) + ISQRT64_OPS + atan2_ops().scaled(2) + DIV64_OPS.scaled(7)
            + OpCounts(alu=120, muls32=16, branches=20))
FOLLOW_OPS = LOOK_OPS + ISQRT64_OPS.scaled(2) + path_follow.STEP_OPS
# the guard's look at one sonar of the ring each step the base drives forward (its angle phi_k
# by a quotient, the range against R_r and the close guard's distance; sonar_guard.py)
GUARD_SONAR_OPS = OpCounts(alu=8, divs=1, branches=2)


def planner_params_001(task_params: TaskParams) -> Params001:
    """001's planner parameters for the task: ``task_params.planner`` (Params001 fields) over a
    sonar ring whose sensors sit ``sonar_offset_mm`` from the centre (the 0.17 m footprint
    circle): ranges are measured from there, η of eq. (15) is taken from the centre. Two
    neighbours reporting the same echo (within ``sonar_shared_echo_mm``) see it in their overlap
    only: eq. (15) would also give each one's own sub-region that echo, and a wall of sectors
    ±0.8 m wide at 2.4 m then blocks every path past an obstacle that is well off it.
    ``ARC_BOUND_001``: eq. (16)'s wedges are cut to the angles of the echo arc grown by R_r
    (host.planning.sonar_regions), else an echo 0.4 m away blocks every start direction within
    ±76 degrees of it, also those leading away from it."""

    tol = task_params.sonar_shared_echo_mm
    sonar = SonarConfig(a_g_rad=task_params.sonar_a_g_mrad / 1000.0,
                        d_e_m=task_params.sonar_d_e_mm / 1000.0,
                        r_r_m=task_params.r_r_mm / 1000.0,
                        sensor_offset_m=task_params.sonar_offset_mm / 1000.0,
                        shared_echo_tol_m=tol / 1000.0 if tol > 0 else None,
                        arc_angle_bound=ARC_BOUND_001)
    # eqs. (5)-(6) for the object's grasp point (``grasp_height_mm``), not 001 §IV's h_e =
    # 0.208 m: the object's top is at 0.10 m (docs/task.md)
    arm = ArmGeometry001(h_e=task_params.grasp_height_mm / 1000.0)
    return Params001(**{"sonar": sonar, "arm": arm, **task_params.planner})


def start_001(now_us: int, x_mm: int, y_mm: int, heading_mrad: int, v_mmps: int,
              obj_xy_mm: tuple[int, int], sonar_mm: tuple, params: Params001 | None = None
              ) -> tuple[Replanner, PathFollower | None, OpCounts, dict]:
    """001's first plan through host.planning.replan.Replanner (which then watches the sonars):
    (replanner, follower or None, ops, detail)."""

    p = params if params is not None else Params001()
    rp = Replanner((obj_xy_mm[0] / 1000.0, obj_xy_mm[1] / 1000.0), p)
    pos, h, vel = state_m(x_mm, y_mm, heading_mrad, v_mmps)
    plan = rp.start(now_us, pos, h, vel, [int(v) for v in sonar_mm])
    detail = {"planner": "001", "reason": plan.reason, "candidates": len(plan.candidates),
              "feasible": sum(1 for c in plan.candidates if c.feasible),
              "plan_arm9_us": plan.ops.time_us()}
    if plan.best is None:
        return rp, None, plan.ops, detail
    fol, ops = path_follower(plan.best, now_us, int(round(p.v_max * 1000)))
    detail["best_ctrl"] = [list(map(float, row)) for row in plan.best.ctrl]
    return rp, fol, plan.ops + ops, detail


def escape_001(rp: Replanner, x_mm: int, y_mm: int, heading_mrad: int, sonar_mm: tuple,
               obj_xy_mm: tuple[int, int], detour_mm: int, side: int = 0
               ) -> tuple[int | None, OpCounts]:
    """001 detour heading (host.planning.escape): the direction nearest the object's bearing
    whose straight ``detour_mm`` + DETOUR_EXTRA_MM stays out of the infeasible regions (eq.
    (16)) of the present reading and of the replanner's memory, grown by DETOUR_MARGIN_MM;
    ``side`` as in host.planning.escape.escape_heading. (heading_mrad or None, ops)"""
    length_mm, margin_mm = detour_mm + DETOUR_EXTRA_MM, DETOUR_MARGIN_MM

    pos, h, _ = state_m(x_mm, y_mm, heading_mrad, 0)
    p = rp.params
    scan = infeasible_regions(p.sonar, pos, h, [int(v) for v in sonar_mm])
    regions = [r for r in scan.regions if not is_object_echo(r, rp.target, p.object_echo_tol_m)]
    goal = atan2_mrad(obj_xy_mm[1] - y_mm, obj_xy_mm[0] - x_mm) / 1000.0
    head, ops = escape_heading(regions + list(rp.memory), pos, h, goal, length_mm / 1000.0,
                               margin_mm / 1000.0, side=side)
    return (None if head is None else int(round(head * 1000))), ops


def straight_clear_001(rp: Replanner, x_mm: int, y_mm: int, heading_mrad: int,
                       sonar_mm: tuple, obj_xy_mm: tuple[int, int], travel_mm: int
                       ) -> tuple[bool, OpCounts]:
    """001: does the straight drive of ``travel_mm`` toward the object (the close approach of
    000 §III.B, which has no obstacle test of its own) stay out of the infeasible regions (eq.
    (16)) of the present reading and of the replanner's memory? (clear, ops)"""

    pos, h, _ = state_m(x_mm, y_mm, heading_mrad, 0)
    p = rp.params
    scan = infeasible_regions(p.sonar, pos, h, [int(v) for v in sonar_mm])
    regions = [r for r in scan.regions if not is_object_echo(r, rp.target, p.object_echo_tol_m)]
    toward = atan2_mrad(obj_xy_mm[1] - y_mm, obj_xy_mm[0] - x_mm) / 1000.0
    return segment_clear(regions + list(rp.memory), pos, toward, max(0, travel_mm) / 1000.0)


def update_001(rp: Replanner, now_us: int, x_mm: int, y_mm: int, heading_mrad: int,
               v_mmps: int, sonar_mm: tuple, force: bool = False
               ) -> tuple[ReplanDecision, PathFollower | None, OpCounts]:
    """001 §III.E: check the rest of the path against fresh sonar, replan when blocked (or
    ``force``: always, the path no longer being followed). Returns (decision, new follower or
    None, ops)."""
    pos, h, vel = state_m(x_mm, y_mm, heading_mrad, v_mmps)
    dec = rp.update(now_us, pos, h, vel, [int(v) for v in sonar_mm], force)
    if not dec.replanned or dec.curve is None:
        return dec, None, dec.ops
    fol, ops = path_follower(dec.curve, now_us, int(round(rp.params.v_max * 1000)))
    return dec, fol, dec.ops + ops


def detour_heading(inp: TaskInputs, obj_xy_mm: tuple, clear_mm: int,
                   heading_mrad: int | None = None) -> dict:
    """The detour's heading: ``heading_mrad`` when the caller found one clear of 001's
    infeasible regions (host.planning.escape), else the free sonar direction nearest the
    object's bearing; with none free a quarter turn left (the next sonar sweep decides again)."""
    if heading_mrad is not None:
        return {"heading_mrad": wrap_mrad(int(heading_mrad)), "drive": True, "from": None,
                "checked": True}
    h = free_heading_nearest(inp, obj_xy_mm, clear_mm)
    if h is None:
        return {"heading_mrad": wrap_mrad(inp.heading_mrad + 1571), "drive": False, "from": None}
    return {"heading_mrad": h, "drive": True, "from": None}





@dataclass
class State001(MethodState):
    """What 001 keeps between steps (the task's ``ms``)."""

    back_offs: int = 0  # moves off a cut symbol made in the run (Method000.search_back_off)
    # the move under way: ("away", detour, heading toward the symbol), ("face", detour, 0) or
    # ("look", stopped_us, 0) (Method001.back_off_move); None: none
    back_off: tuple | None = None
    cut_first_us: int | None = None  # the first frame of the cut symbol not yet moved off
    cut_seen_us: int | None = None  # the last frame of the symbol cut at the bottom (not 001's)
    cut_heading_mrad: int = 0  # ... and the odometry heading it was seen in

    replanner: Replanner | None = None  # the plan of eq. (17) and its sonar memory (§III.E)
    path_from: tuple[int, int] | None = None  # odometry place the last planned path began at
    v0_div: int = 1  # the planner's v0 divided by this (a fallback step, start_detour)
    fallbacks: int = 0  # fallback steps taken with no feasible curve
    detour: dict | None = None  # a drive aside after no feasible curve (detour_step)
    detours: int = 0
    detour_side: int = 0  # +1: the detours go round left of the object's bearing, -1 right
    # arrived on the grasp circle: the estimate the look before the grasp is to confirm
    circle_expected: tuple[int, int] | None = None
    circle_l_e_mm: int = 0  # ... and the circle's radius l_e
    circle_adjusts: int = 0  # ... and the grasp's close-ins then (Task.sight_adjusts)
    ik_grasp: bool = False  # PRECISE_GRASP goes down by eq. (11), no spoke alignment


class Method001(Method000):
    """001: 000's hooks with the sonar planning of 001 (host/task/method.py)."""

    name = "001"
    State = State001
    # 001 §IV's values and their ranges
    paper_params = {
        "Vmax": Param(float, 0.4, 0.01, 1.0, "m/s, speed limit"),
        "Amax": Param(float, 0.1, 0.001, 2.0, "m/s^2, acceleration limit"),
        "R_r": Param(float, 0.2, 0.05, 1.0, "m, safety radius"),
        "k_s": Param(int, 5, 2, 5, "sonars (5 fitted)"),
        # a cone under pi: the sonar regions' arcs need 0 < A_g < pi (SonarConfig), and the
        # world and the task read it in whole mrad (3142 would be past pi)
        "A_g": Param(float, 1.05, 0.05, 3.14, "rad, sonar cone"),
        "D_e": Param(float, 2.5, 0.1, 10.0, "m, sonar range"),
        "h_e": Param(float, 0.208, 0.01, 1.0, "m"),
        "n_e": Param(int, 36, 1, 360, "end points on the grasp circle"),
        "v0": Param(float, 0.2, 0.01, 1.0, "m/s, cruise speed"),
        "T_s": Param(float, 0.5, 0.05, 2.0, "s, sampling period of the path"),
        "k1": Param(float, 0.8, 0.0, 10.0, "weight of the path length"),
        "k2": Param(float, 0.2, 0.0, 10.0, "weight of the curvature"),
        "T_D": Param(float, 15.0, 0.0, 100.0, "cm, clearance threshold"),
    }
    not_used_params = ("h_e",)
    param_order = (("v0", "Vmax", 0.0),)
    # k_s, A_g and D_e are also read by the world (its sonar ring)
    paper_to_task = {
        "Vmax": ("planner", "v_max", float), "Amax": ("planner", "a_max", float),
        "v0": ("planner", "v0", float), "T_s": ("planner", "t_s", float),
        "k1": ("planner", "k1", float), "k2": ("planner", "k2", float),
        "T_D": ("planner", "t_d_m", lambda v: float(v) / 100.0),  # T_D read as cm
        "n_e": ("planner", "n_e", int),
        "R_r": (None, "r_r_mm", mrad),  # m -> mm
        "A_g": (None, "sonar_a_g_mrad", mrad), "D_e": (None, "sonar_d_e_mm", mrad)}
    scene = SceneHints("radial-symbol", 180.0, obstacles=True)
    robot = "001"
    object_given = True
    link_lengths_mm = (160.0, 160.0, 200.0)
    # 001 comes at the object from any side: the "+" pair is often seen along the view, where
    # at one depth it comes out 25 mm apart instead of 47.3 mm (and is refused)
    plus_on_top = True
    adjust_keeps_posture = False  # the long arm looks from the close-look posture
    # ADJUST ends on odometry (blind_finish_mm): near, the long arm's camera is over the card
    # and loses the pair. The base stopped, the camera looks back at the top from 140-200 mm
    # (reachable views, first wins), where the pair fits the frame, and the grasp goes on that
    # sighting (host/task/grasp.py, docs/task.md "001: the look before the grasp")
    sight_views = ((180, 900), (160, 1000), (180, 1000), (200, 800), (160, 1100), (140, 1100))
    # SEARCH reads the cut symbol as 000 does (search_back_off)
    detectors = {**Method000.detectors, "ROUGH_GRASP": ("dual_plus",)}
    # the precise grasp's w_T <= w_max = 40 px needs the camera >= 92 mm above the "+"
    # (6 mm * 611 / 92): looking down, the 001 arm reaches 95 mm there within 142 mm of the
    # waist only, so ADJUST ends the object 108-132 mm ahead and the hover is 95 mm (39 px);
    # the long 001 arm puts the camera ahead of a close object: finish on odometry sooner
    param_defaults = {"h_shoulder_mm": 108, "grasp_r_mm": 120, "grasp_r_tol_mm": 12,
                      "hover_mm": 95,
                      "blind_finish_mm": 250, "max_plan_attempts": 6}
    # 000's searches after a loss near the object (000 §III.B.2, §III.C) are not 001's: the
    # usual search, and the rough position when no spoke is seen
    lost_search = Method.lost_search
    grasp_lost = Method.grasp_lost
    back_offs_max = BACK_OFFS_001
    cut_look_us = 0  # 001 moves off a cut symbol wherever it is seen (back_off_here)

    # --- SEARCH: away from a cut symbol --------------------------------------------------------
    def search_back_off(self, t: Task, now: int, inp: TaskInputs, dets: dict) -> bool:
        """000's move off a cut symbol (:meth:`back_off_move`), and the same move off the
        estimate when the search has looked all round where it stands without a frame of the
        object: an object the camera never saw (P_i carried on odometry) whose estimate is
        within UNSEEN_NEAR_MM of the axle may stand nearer than the radial symbol is read, cut
        in a few frames or in none, and the wander's legs, farther out, pass it by. The base
        faces away from the estimate, drives CUT_AWAY_MM off it, faces it again and searches
        anew (a ``back_off_unseen`` detail event); counted with the cut moves."""
        ms = t.ms
        if ms.back_off is None and ms.back_offs < self.back_offs_max \
                and self.unseen_near(t, inp):
            dx, dy = t.obj[0] - inp.x_mm, t.obj[1] - inp.y_mm
            turn = wrap_mrad(atan2_mrad(dy, dx) - inp.heading_mrad)
            ms.back_offs += 1
            ms.back_off = self.back_off_first(t, inp, turn)
            ms.cut_first_us = None  # a cut seen from here says nothing of the next place
            t.note(back_off_unseen={"dist_mm": isqrt(dx * dx + dy * dy), "n": ms.back_offs,
                                    "turn_mrad": turn})
        return super().search_back_off(t, now, inp, dets)

    @staticmethod
    def unseen_near(t: Task, inp: TaskInputs) -> bool:
        """The search's look-around here is over (``turns_per_wander`` cycles), nothing is being
        confirmed or driven to, the object was never seen by the camera (or not since a blind
        grasp on its estimate found no evidence, grasp.py) and its estimate is within
        UNSEEN_NEAR_MM of the axle."""
        if t.object_sighted or t.obj is None or t.confirm_until is not None \
                or t.far is not None or t.search is None \
                or t.search.cycle < t.search.params.turns_per_wander:
            return False
        dx, dy = t.obj[0] - inp.x_mm, t.obj[1] - inp.y_mm
        return dx * dx + dy * dy <= UNSEEN_NEAR_MM * UNSEEN_NEAR_MM

    def back_off_here(self, t: Task, inp: TaskInputs) -> bool:
        """001 comes near its object anywhere (P_i and odometry, the grasp circle): its move
        off a cut symbol drives forward, the sonar ring watching, so it is made wherever
        SEARCH sees one."""
        return True

    def back_off_due(self, t: Task, now: int) -> bool:
        """Not at the first frame of the cut symbol: a symbol in range is cut too as the
        search's sweep brings it into the frame, and read whole a few frames later
        (docs/task.md). Due at a frame CUT_WAIT_US or more after the first that showed it,
        within CUT_STALE_US (older: this one is the first)."""
        first = t.ms.cut_first_us
        if first is None or now - first > CUT_STALE_US:
            t.ms.cut_first_us = now
            return False
        if now - first < CUT_WAIT_US:
            return False
        t.ms.cut_first_us = None
        return True

    def back_off_first(self, t: Task, inp: TaskInputs, turn: int) -> tuple:
        """Face away from the symbol (``turn`` + pi) and drive CUT_AWAY_MM off it: the radial
        symbol is read from 0.45 m ahead of the camera (docs/markers.md), the camera ~0.1 m
        ahead of the axle in the search posture, and a symbol cut in SEARCH after a loss can be
        0.2 m from the axle."""
        toward = wrap_mrad(inp.heading_mrad + turn)
        away = {"heading_mrad": wrap_mrad(toward + 3142), "drive": True, "from": None,
                "length_mm": CUT_AWAY_MM}
        return ("away", away, toward)

    def back_off_move(self, t: Task, now: int, inp: TaskInputs) -> bool:
        """The drive away (a detour of host/task/sonar_guard.py: turn, then drive, stopping for
        an echo ahead), then the turn back to face the symbol."""
        ms = t.ms
        phase, d, toward = ms.back_off
        if phase == "away":
            if not drive_detour(t, inp, d):
                return True
            phase, d, toward = ms.back_off = (
                "face", {"heading_mrad": toward, "drive": False, "from": None}, 0)
        if phase == "face":
            if not drive_detour(t, inp, d):
                return True
            ms.back_off = ("look", now, 0)
        return False

    # --- APPROACH: eq. (17) with the sonar ring, replanned (§III.E) ---------------------------
    def plan(self, t: Task, now: int, inp: TaskInputs
             ) -> tuple[PathFollower | None, OpCounts, dict]:
        if t.ms.replanner is not None and t.obj == t.plan_obj:
            # same object: the replanner keeps its remembered regions and slows down (replan.py);
            # a plan is asked for with no path followed (stopped by the guard, a detour, a
            # failed plan), so it plans from here even when its last curve looks clear
            dec, follower, ops = update_001(t.ms.replanner, now, inp.x_mm, inp.y_mm,
                                            inp.heading_mrad, inp.v_mmps, inp.sonar_mm,
                                            force=True)
            detail = {"planner": "001", "reason": dec.reason}
            if dec.curve is not None:
                detail["best_ctrl"] = [list(map(float, row)) for row in dec.curve.ctrl]
            return follower, ops, detail
        params = planner_params_001(t.p)
        if t.ms.v0_div > 1:  # a fallback step (start_detour)
            params = replace(params, v0=params.v0 / t.ms.v0_div)
        t.ms.replanner, follower, ops, detail = start_001(
            now, inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps, t.obj, inp.sonar_mm, params)
        if follower is not None:
            t.ms.path_from = (inp.x_mm, inp.y_mm)  # a fallback backs off toward here
        return follower, ops, detail

    def look_first(self, t: Task, now: int, inp: TaskInputs) -> bool:
        """Ours: P_i given (001 §II) and the object near, unseen: turn in place to face it with
        the camera on it for up to ``LOOK_FIRST_US`` before the first plan. The radial symbol is
        seen 0.45-1.0 m ahead (docs/markers.md); the curve to the grasp circle of an object
        this near ends inside that range, and the arm keeps its folded start posture while the
        base first turns, so the camera never saw the object and the grasp on P_i and odometry
        (3 % wheel slip) closed 40 mm beside it (docs/task.md). True while looking."""
        if t.object_sighted or now - t.entered_us >= LOOK_FIRST_US:
            return False
        x, y = t.obj_platform(inp)
        if not LOOK_FIRST_MM[0] * 16 <= isqrt(x * x + y * y) <= LOOK_FIRST_MM[1] * 16:
            return False
        bearing = atan2_mrad(x, y + t.p.mount_forward_mm * 16)  # seen from the axle
        # the search's look (host.search), the camera high and back: the posture adjustment
        # reaches the long arm's camera out to 0.2 m of an object this near, too near to see it
        sp = SearchParams(**t.p.search)
        t.set_arm(now, sp.coarse_theta2_mrad[0], sp.theta3_mrad, sp.theta4_mrad,
                  atan2_mrad(x, y))
        if abs(bearing) <= t.p.bearing_tol_mrad:
            t.wheels = (0, 0)
        else:
            t.wheels = turn_in_place(-1 if bearing > 0 else 1, t.p.turn_wheel_mmps)
        return True

    def sighting_usable(self, t: Task, now: int, inp: TaskInputs) -> bool:
        """Not while the base turned faster than SIGHTING_MAX_TURN_MRAD_S over the last frame
        latency. Ours: the frame's capture time is known only as ``frame_latency_us`` ago (the
        vision time varies by 10-25 ms), and the arm history holds servo targets, not where the
        lagging servos were; at 1.5 rad/s (a tight 001 curve at low speed, a_t = v²κ allows it)
        a sighting 0.4 m away is tens of mm off and the grasp on it misses (docs/cosim.md
        "Measured", T2). The given P_i or an earlier sighting is kept instead."""
        if not t.pose_hist:
            return True
        then = t.pose_at(now - t.p.frame_latency_us)
        dt = max(1, now - then[0])
        rate = abs(wrap_mrad(inp.heading_mrad - then[3])) * 1_000_000 // dt
        return rate <= SIGHTING_MAX_TURN_MRAD_S

    def sonar_replan(self, t: Task, now: int, inp: TaskInputs, moved: bool) -> bool | None:
        """001 §III.E: every ``replan_period_us`` the sonars check the rest of the path; blocked
        -> replan from here."""
        if not (now - t.plan_us >= t.p.replan_period_us and t.follower is not None
                and not moved and t.ms.replanner is not None):
            return None
        dec, follower, ops = update_001(t.ms.replanner, now, inp.x_mm, inp.y_mm,
                                        inp.heading_mrad, inp.v_mmps, inp.sonar_mm)
        if dec.plan is None:
            t.charge(ops)
        else:  # the plan's time in slices; its path (if any) is taken after the last one
            t.plan_job = PlanJob.start(follower if dec.replanned else None, None, ops)
            t.charge(t.plan_job.step())
        t.plan_us = now
        if dec.replanned:
            t.counters["plans"] += 1
            t.note(replan=dec.reason, plan={
                "planner": "001", "reason": dec.reason,
                "best_ctrl": [list(map(float, row)) for row in dec.curve.ctrl]})
        elif dec.blocked and dec.curve is not None:
            t.note(replan=dec.reason)  # blocked far ahead, no update yet: path kept
        elif dec.curve is None:
            t.follower = None  # nothing feasible: stop; the next step plans afresh
            t.note(replan=dec.reason)
            t.wheels = (0, 0)
            return True
        return False

    def start_path(self, t: Task, follower: PathFollower, now: int) -> PathFollower:
        """The path and the replanner's curve start now (the plan's last slice)."""
        t.ms.replanner.start_path(now)
        return super().start_path(t, follower, now)

    def hold_before_plan(self, t: Task, now: int, inp: TaskInputs) -> bool:
        """The first plan waits for one full sonar sweep; a detour is driven to its end; a
        new plan is made from standstill."""
        if t.ms.replanner is None and self.look_first(t, now, inp):
            return True
        if t.ms.replanner is None and now - t.entered_us < t.p.sonar_sweep_us:
            t.wheels = (0, 0)
            return True
        if t.ms.detour is not None:
            if not self.detour_step(t, inp):
                return True
            t.ms.detour, t.plan_us = None, now  # done: stop, then plan afresh from here
        if t.follower is None and t.ms.replanner is not None and (
                now - t.plan_us < 500_000 or abs(inp.v_mmps) > 30):
            t.wheels = (0, 0)  # stop first, then replan from standstill
            return True
        return False

    def way_blocked(self, t: Task, inp: TaskInputs, dist_mm: int) -> bool:
        """An echo straight ahead well short of the object (its own echo is ~170 mm short of
        the waist distance: ring 70 mm ahead of the waist plus its radius), or the straight
        way to the object crossing an infeasible region of eq. (16) (an obstacle beside the
        line, unseen by the front sonar; docs/cosim.md "Measured", T1)."""
        n = len(inp.sonar_mm)
        echo = n >= 3 and 0 < int(inp.sonar_mm[n // 2]) < dist_mm - 300
        return echo or not self.straight_clear(t, inp, dist_mm)

    def start_detour(self, t: Task, inp: TaskInputs) -> bool:
        """Obstacles across the way and no feasible curve from here: fall back in steps
        (``FALLBACKS``, each a ``fallback`` detail event), then plan again: a lower v0 (the
        slower end speed of eq. (9) gives the candidates more room under A_max), a short
        back-off toward where the last path began, a turn in place toward the widest free
        sonar sector, then drives aside through free sonar space (host.planning.escape; at
        most ``max_detours``)."""
        step = FALLBACKS[min(t.ms.fallbacks, len(FALLBACKS) - 1)]
        if step == "detour" and t.ms.detours >= t.p.max_detours:
            return False
        t.ms.fallbacks += 1
        t.note(fallback={"step": step, "n": t.ms.fallbacks})
        if step == "lower_v0":
            t.ms.v0_div *= 2
            t.ms.replanner = None  # planned afresh with the lower v0 (planner_params_001)
            return True
        if step == "widest_sector":
            t.ms.detour = {"heading_mrad": widest_free_heading(inp, t.p.detour_clear_mm),
                        "drive": False, "from": None}
            return True
        if step == "back_off":
            # facing (and driving, the sonars watching) back toward where the last path began
            fx, fy = t.ms.path_from if t.ms.path_from is not None else (inp.x_mm, inp.y_mm)
            if (fx - inp.x_mm) ** 2 + (fy - inp.y_mm) ** 2 < BACK_OFF_MM * BACK_OFF_MM:
                return self.start_detour(t, inp)  # nowhere to back off to: the next step
            t.ms.detour = {"heading_mrad": atan2_mrad(fy - inp.y_mm, fx - inp.x_mm),
                        "drive": True, "from": None, "length_mm": BACK_OFF_MM}
            return True
        t.ms.detours += 1
        head, ops = escape_001(t.ms.replanner, inp.x_mm, inp.y_mm, inp.heading_mrad,
                               inp.sonar_mm, t.obj, t.p.detour_mm, t.ms.detour_side)
        t.charge(ops)
        if head is not None and not t.ms.detour_side:  # keep to the first one's side
            off = wrap_mrad(head - atan2_mrad(t.obj[1] - inp.y_mm, t.obj[0] - inp.x_mm))
            t.ms.detour_side = (off > 0) - (off < 0)
        t.ms.detour = detour_heading(inp, t.obj, t.p.detour_clear_mm, head)
        t.note(detour=dict(t.ms.detour), detour_count=t.ms.detours)
        return True

    follow_ops = FOLLOW_OPS

    def path_wheels(self, cmd: WheelCommand) -> tuple[int, int]:
        """Ours: 001's sonar ring (S_1..S_k_s, ±π/2 about the heading) sees nothing behind the
        base, so it never backs up: where the follower would reverse (its reference fell
        behind in a tight loop) it turns on the spot instead and the sonar check replans
        (docs/cosim.md "Measured", T3)."""
        if cmd.left_mm_s + cmd.right_mm_s < 0:
            turn = (cmd.right_mm_s - cmd.left_mm_s) // 2
            return -turn, turn
        return cmd.left_mm_s, cmd.right_mm_s

    # the curve ends on the grasp circle, the object ~l_e - mount_forward_mm (~206 mm) ahead of
    # the waist: cut short only with the object already at ADJUST's goal, or 60 mm (its 20 mm
    # radius and 40 mm for the estimate's error) from the footprint once braked: a curve
    # planned for an older estimate can end well inside the present one's circle
    near_margin_mm = 0
    object_clear_mm = 60

    def path_end(self, t: Task, now: int, inp: TaskInputs, why: str, error_mm: int | None
                 ) -> None:
        """On the grasp circle (001 §III.B.1, eqs. (5)-(6), l_e for the object's grasp
        height): the base stops, ROUGH_GRASP looks back at the object and grasps by eq. (11)
        when the look confirms it (:meth:`look_decides`). The arrival's error, the axle's
        distance from the estimate less l_e, goes in the trace (``grasp_circle``; a start
        already on the circle has no path and no ``path_error_mm``)."""
        l_e_mm = int(round(grasp_radius(planner_params_001(t.p).arm).l_e_m * 1000))
        axle_mm = isqrt((t.obj[0] - inp.x_mm) ** 2 + (t.obj[1] - inp.y_mm) ** 2)
        x, y = t.obj_platform(inp)
        t.note(grasp_circle={"l_e_mm": l_e_mm, "axle_mm": axle_mm,
                             "error_mm": axle_mm - l_e_mm, "path_error_mm": error_mm,
                             "waist_mm": isqrt(x * x + y * y) // 16})
        t.ms.circle_expected, t.ms.circle_l_e_mm = t.obj, l_e_mm
        t.ms.circle_adjusts = t.sight_adjusts
        t.go(now, "ROUGH_GRASP", "on the grasp circle: " + why)

    def look_decides(self, t: Task, now: int, inp: TaskInputs) -> bool:
        """After the look from the grasp circle: the object seen (dual "+", never its absence)
        within ``CIRCLE_CONFIRM_MM`` of where the base expected it, and its grasp point
        reachable by eq. (11) of 000 (gripper down) from here: the gripper goes above the
        grasp point, then down and closes (PRECISE_GRASP, ``grasp_close`` "ik"); the grasp
        check of LIFT decides. Else 000's ADJUST and precise grasp from here, as before the
        grasp from the circle (an object the camera never saw is then searched for after
        ADJUST's look, grasp.py)."""
        expected = t.ms.circle_expected
        if expected is None:
            return False
        t.ms.circle_expected = None
        if t.sight_adjusts != t.ms.circle_adjusts:
            return False  # the base closed in since the arrival: 000's grasp from here
        off_mm = isqrt((t.obj[0] - expected[0]) ** 2 + (t.obj[1] - expected[1]) ** 2)
        why, pre = None, None
        if not t.sight_frames:
            why = "not seen by the look"
        elif off_mm > CIRCLE_CONFIRM_MM:
            why = f"seen {off_mm} mm from where expected"
        else:
            grasp = GRASP.object_target_q4(t, inp, t.p.grasp_height_mm)
            down = t.grasp_ik(grasp)
            for up_mm in range(CIRCLE_PRE_MM, t.p.object_top_mm - t.p.grasp_height_mm - 1,
                               -10):
                pre = t.grasp_ik((grasp[0], grasp[1], grasp[2] + up_mm * 16))
                if isinstance(pre, kinematics.ArmPose):
                    break
            if isinstance(down, kinematics.Unreachable):
                why = f"grasp point out of reach: {down.reason}"
            elif not isinstance(pre, kinematics.ArmPose):
                why = "no reachable pose above the grasp point"
        # the arrival's error as the look sees it: the axle's distance from the sighted object
        # less l_e (the base stood still since the arrival)
        axle_mm = isqrt((t.obj[0] - inp.x_mm) ** 2 + (t.obj[1] - inp.y_mm) ** 2)
        t.note(circle_look={"frames": t.sight_frames, "off_mm": off_mm,
                            "error_mm": axle_mm - t.ms.circle_l_e_mm, "confirmed": why is None})
        if why is None:
            t.ms.ik_grasp = True
            t.grasp_xy_q4 = grasp[:2]
            t.grasp_alpha = pre.alpha_mrad
            t.phase = ""
            t.apply_pose(now, pre)
            t.note(ik_pre_pose_mrad=[pre.theta2_mrad, pre.theta3_mrad, pre.theta4_mrad,
                                     pre.theta5_mrad])
            return True
        t.go(now, "ADJUST", f"the look from the grasp circle did not confirm the object "
             f"({why}): vision-based adjustment and precise grasp")
        return True

    def enter_precise(self, t: Task, now: int, inp: TaskInputs) -> None:
        """After the confirmed look from the grasp circle, straight down to the grasp point
        and close (eq. (11) of 000, no spoke alignment); else 000's precise grasp (and a look
        from the circle that never came, no view being reachable, is not waited for)."""
        if not t.ms.ik_grasp:
            t.ms.circle_expected = None
            super().enter_precise(t, now, inp)
            return
        t.ms.ik_grasp = False
        GRASP.descend(t, now, "eq. (11) from the grasp circle, the object confirmed by the look",
                      "ik")

    def straight_clear(self, t: Task, inp: TaskInputs, dist: int) -> bool:
        """The close approach's straight way to the object (``dist`` from the waist, to stop
        ``grasp_r_mm`` short) misses the infeasible regions of eq. (16)."""
        if t.ms.replanner is None:
            return False
        clear, ops = straight_clear_001(t.ms.replanner, inp.x_mm, inp.y_mm, inp.heading_mrad,
                                        inp.sonar_mm, t.obj, dist - t.p.grasp_r_mm)
        t.charge(ops)
        return clear


    def guard_wheels(self, t: Task, now: int, inp: TaskInputs) -> None:
        """Last line of the no-contact rule: while the base would move forward in SEARCH or
        APPROACH, a sonar of the front half of the ring (|phi_k| < pi/2) reading below the
        safety circle R_r (``r_r_mm``; 001 §III.C.2) stops it and drops the path, so that no
        plan is followed further before one is made from the fresh ranges. The object's own
        echo (its estimate inside that sonar's cone, at the range read +- ``GUARD_OBJECT_MM``)
        does not count: APPROACH ends with the object at arm's length. In APPROACH the
        base then turns in place toward the widest free sector and drives ``GUARD_OUT_MM``
        along it before it plans again: a plan from standstill starts forward, into the echo,
        and was stopped again at once; a plan from the turned pose bends back toward the
        object, into the echo, and so did the detours, each stopped at its first step."""
        if t.wheels[0] + t.wheels[1] > 0 and len(inp.sonar_mm) >= 2:
            t.charge(GUARD_SONAR_OPS.scaled(len(inp.sonar_mm)))
        close_guard(t, now, inp)
        guard = guard_stop(t, inp, GUARDED_STATES)
        if guard is None:
            return
        if t.state == "APPROACH":
            # a new plan from here starts forward, into what the guard saw, and is stopped
            # again at once: first turn toward the widest free sector and leave R_r
            t.ms.detour = out_of_r_r(inp, t.p.detour_clear_mm)
            guard["turn_to_mrad"] = t.ms.detour["heading_mrad"]
        t.note(sonar_guard=guard)

    def detour_step(self, t: Task, inp: TaskInputs) -> bool:
        """One step of the detour (host/task/sonar_guard.py ``drive_detour``); True when it is
        over (the caller plans again)."""
        return drive_detour(t, inp, t.ms.detour)


RULES = Method001()
