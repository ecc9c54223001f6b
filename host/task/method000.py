"""Paper 000's method: radial symbol, Bezier path of eq. (9), dual "+", spoke, gripper down.

SEARCH looks for the radial symbol (000 §III.A); APPROACH follows the best Bezier curve of
eq. (9) (host.planning.bezier000) toward the stand-off point; ADJUST closes in on the dual "+"
(§III.B); ROUGH_GRASP hovers above the nearer "+" with the gripper pitched alpha_T = -pi/2 by
eq. (11); PRECISE_GRASP rolls to pi/2 and aligns on the spoke (§III.C.2); the grasp check of
LIFT's grasp check asks for the held object filling the hand camera's frame (grasp.py,
docs/task.md). Lost near the
object (ADJUST, PRECISE_GRASP), the platform stops and the arm searches by Fig. 5 with the
paper's d_theta2 (``lost_search``, ``grasp_lost``; docs/task.md). A symbol too near to be seen
whole at the start is backed off from (``search_back_off``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from mobigrasp.host import kinematics
from mobigrasp.host.control.path_follow import PathFollower, Trajectory
from mobigrasp.host.fixedpoint import atan2_mrad
from mobigrasp.host.planning.bezier000 import Params000, plan_000
from mobigrasp.host.search import ArmSearch, SearchParams
from mobigrasp.host.task.approach import PathMethod
from mobigrasp.host.task.drive import turn_in_place, velocity_m, wrap_mrad
from mobigrasp.host.task.grasp import GRASP
from mobigrasp.host.task.method import K_THETA, PI, MethodState, Param, SceneHints, mrad, q12
from mobigrasp.host.task.sense import CAMERA_000, odom_to_platform_q4
from mobigrasp.host.vision import registry

if TYPE_CHECKING:
    from mobigrasp.host.budget import OpCounts
    from mobigrasp.host.control.path_follow import WheelCommand
    from mobigrasp.host.kinematics import ArmGeometry, ArmPose, Unreachable
    from mobigrasp.host.task.machine import Task, TaskInputs
    from mobigrasp.host.task.params import TaskParams
    from mobigrasp.host.vision.dual_plus import DualPlus
    from mobigrasp.host.vision.radial_symbol import RadialSymbol

MAX_TRACE_CANDIDATES = 40  # candidate curves kept in the trace for the plots (evenly picked)
# SEARCH: the radial symbol cut by the frame's border (radial_symbol.py detect_radial_cut) is
# nearer than its near limit (0.45 m from the camera): turn toward it, back straight off
# BACK_OFF_000_MM at slow_mmps and look around again. Only from the run's start (within
# BACK_OFF_FROM_MM of the odometry's origin, before any loss): the sonar ring does not look
# back, and the generator keeps 0.35 m clear around a start, the footprint's radius being
# 170 mm; so at most BACK_OFFS_000 a run (docs/task.md, "000: the back-off ...")
BACK_OFF_000_MM = 150
BACK_OFF_FROM_MM = 40
BACK_OFFS_000 = 1
# SEARCH: a wander leg stopped short by an obstacle ahead within CUT_LOOK_000_US of a frame that
# showed the symbol cut by the frame's bottom, a flat arc at least CUT_LOOK_FLAT times wider than
# high (the object itself may have stopped it, 0.5-0.6 m from the camera: beyond the near
# limit, below the sweep's far level; an obstacle's face near the camera is a taller box) faces
# it and ends in a cycle at rest there before the next station (docs/task.md "000: a ring's leg
# stopped by an obstacle")
CUT_LOOK_000_US = 3_000_000
CUT_LOOK_FLAT = 3
# SEARCH's wander (docs/task.md "000: the sweep while driving", "000: the last ring nearer the
# edge"): the waist steps 0.35 rad with one frame per pose while driving at WANDER_000_MMPS;
# legs that keep OUTWARD_FROM_000_MM from the start sweep the outer side and
# OUTWARD_INWARD_000_MRAD across alone: the last ring of the 4.5 m disc, EDGE_000_MM inside its
# edge (3.6 m), sees 0.9 m outward to the edge and ~0.7 m inward, where the first ring's strip
# (its sides at 2.07 m) ends
WANDER_000_MMPS = 350
WANDER_D_THETA5_000_MRAD = 350
OUTWARD_FROM_000_MM = 3000
OUTWARD_INWARD_000_MRAD = 1050
EDGE_000_MM = 900
# SEARCH: a sighting not seen again at rest, farther from the axle than this +
# sighting_match_mm, is driven to until this far (the camera then ~0.65 m from it, well inside
# the symbol's 1.1 m range) and looked at before it is dropped (docs/task.md "000: a far
# sighting driven to")
SIGHTING_APPROACH_000_MM = 850
# a leg of the last ring stopped by an obstacle goes round it and aims at its station again,
# at most ROUND_TRIES_000 times until a leg ends unblocked (docs/task.md "000: a ring's leg
# stopped by an obstacle")
ROUND_TRIES_000 = 2


def plan_follower(now_us: int, x_mm: int, y_mm: int, heading_mrad: int, v_mmps: int,
                  obj_xy_mm: tuple[int, int], planner_params: Params000 | None = None
                  ) -> tuple[PathFollower | None, OpCounts, dict]:
    """Plan with 000's planner from the pose toward the object; (follower, ops, detail).

    ``detail`` holds what the trace needs for the plots: candidate count, feasible count, the
    reason, the chosen control points and the modelled ARM9 time of the plan."""
    h = heading_mrad / 1000.0
    start = (x_mm / 1000.0, y_mm / 1000.0)
    vel = velocity_m(v_mmps, heading_mrad)
    target = (obj_xy_mm[0] / 1000.0, obj_xy_mm[1] / 1000.0)
    p = planner_params if planner_params is not None else Params000()
    plan = plan_000(start, vel, target, p, heading_rad=h)
    n_feasible = sum(1 for cand in plan.candidates if cand.feasible)
    step = max(1, len(plan.candidates) // MAX_TRACE_CANDIDATES)
    cands = [[list(map(float, row)) for row in plan.candidates[i].curve.ctrl]
             for i in range(0, len(plan.candidates), step)]
    detail: dict = {"planner": "000", "reason": plan.reason,
                    "candidates": len(plan.candidates), "feasible": n_feasible,
                    "plan_arm9_us": plan.ops.time_us(), "candidates_ctrl": cands}
    if plan.best is None:
        return None, plan.ops, detail
    traj = Trajectory.from_curve(plan.best)
    limit = int(round(p.v_max * 1000))
    detail["best_ctrl"] = [list(map(float, row)) for row in plan.best.ctrl]
    detail["duration_us"] = traj.duration_us
    return PathFollower(traj, now_us, limit), plan.ops + traj.ops, detail


@dataclass
class State000(MethodState):
    """What 000 keeps between steps (the task's ``ms``)."""

    grasp_searches: int = 0  # searches after a loss in PRECISE_GRASP (grasp_lost)
    back_offs: int = 0  # back-offs from a cut symbol made in the run (search_back_off)
    # the last frame that showed the symbol cut by the frame's bottom, flat (search_back_off)
    cut_seen_us: int | None = None
    cut_heading_mrad: int = 0  # ... and the odometry heading it was seen in
    # the back-off under way: ("turn", heading_from, turn_mrad), ("back", x0_mm, y0_mm) or
    # ("look", stopped_us, 0); None: none
    back_off: tuple[str, int, int] | None = None


class Method000(PathMethod):
    """000: the hooks of the machine's states (host/task/method.py)."""

    name = "000"
    State = State000
    # 000 §IV's values and their ranges
    paper_params = {
        "k_s": Param(int, 5, 1, 20, "samples"),
        "T_s": Param(float, 0.3, 0.05, 2.0, "s, sampling period of the path"),
        "k1": Param(float, 0.5, 0.0, 10.0, "weight of the path length"),
        "k2": Param(float, 0.5, 0.0, 10.0, "weight of the curvature"),
        "theta2_min": Param(float, -2.8, -3.0, 0.0, "rad, wrist pitch (joint table)"),
        "theta2_max": Param(float, -2.1, -3.0, 0.0, "rad, wrist pitch (joint table)"),
        "theta5_min": Param(float, -0.8, -1.4, 1.4, "rad, waist yaw (joint table)"),
        "theta5_max": Param(float, 0.8, -1.4, 1.4, "rad, waist yaw (joint table)"),
        "dtheta2_l": Param(float, 0.06, 0.005, 0.5, "rad, search step of the wrist"),
        "k_theta2": Param(float, 1.0, 0.0, 10.0, "gain"),
        "k_theta3": Param(float, 0.0, 0.0, 10.0, "gain"),
        "k_theta4": Param(float, 0.0, 0.0, 10.0, "gain"),
        "alpha_T": Param(float, -PI / 2, -PI, 0.0, "rad, camera pitch at the grasp"),
        "w_min": Param(int, 20, 1, 320, "px, window"),
        "w_max": Param(int, 40, 1, 320, "px, window"),
        "v0_mps": Param(float, 0.12, 0.01, 1.0, "m/s, cruise speed"),
        "vmax_mps": Param(float, 0.25, 0.01, 1.0, "m/s, speed limit"),
        "amax_mps2": Param(float, 0.04, 0.001, 2.0, "m/s^2, acceleration limit"),
        "rmin_m": Param(float, 0.1, 0.01, 2.0, "m, turning radius limit"),
        "l_w": Param(float, 0.3, 0.1, 1.0, "m, wheel track"),
        "L_m": Param(float, 0.109, 0.01, 0.5, "m, outer ring diameter"),
        "D_act_m": Param(float, 0.0473, 0.005, 0.5, "m, distance of the two + centres"),
    }
    # k_s (spoke points), alpha_T (the gripper pitch is chosen by the grasp IK), l_w (the
    # plant's track), L_m and D_act_m (the marker as printed)
    not_used_params = ("k_s", "alpha_T", "l_w", "L_m", "D_act_m")
    # a joint range of the search at least 0.01 rad wide (the host works in mrad), the
    # window w_min <= w_max, v0 <= vmax
    param_order = (("theta2_min", "theta2_max", 0.01), ("theta5_min", "theta5_max", 0.01),
                   ("w_min", "w_max", 0), ("v0_mps", "vmax_mps", 0.0))
    paper_to_task = {
        "T_s": ("planner", "t_s", float), "k1": ("planner", "k1", float),
        "k2": ("planner", "k2", float), "v0_mps": ("planner", "v0", float),
        "vmax_mps": ("planner", "v_max", float), "amax_mps2": ("planner", "a_max", float),
        "rmin_m": ("planner", "r_min", float),
        "theta2_min": ("search", "theta2_min_mrad", mrad),
        "theta2_max": ("search", "theta2_max_mrad", mrad),
        "theta5_min": ("search", "theta5_min_mrad", mrad),
        "theta5_max": ("search", "theta5_max_mrad", mrad),
        "dtheta2_l": ("search", "d_theta2_mrad", mrad),
        "w_min": (None, "w_min_px", int), "w_max": (None, "w_max_px", int),
        # eq. (10)'s gains, one Q12 triple of host.posture (000 §IV: 1, 0, 0)
        "k_theta2": (K_THETA, 0, q12), "k_theta3": (K_THETA, 1, q12),
        "k_theta4": (K_THETA, 2, q12)}
    scene = SceneHints("radial-symbol", 150.0)
    robot = "000"
    link_lengths_mm = (95.5, 89.0, 97.0)
    camera = CAMERA_000
    # the wander: one frame per waist pose of 0.35 rad while driving, faster; the last ring's
    # legs sweeping outward alone
    param_defaults: dict = {"wander_mmps": WANDER_000_MMPS,
                            "sighting_approach_mm": SIGHTING_APPROACH_000_MM,
                            "search": {"wander_frames_per_pose": 1,
                                       "wander_d_theta5_mrad": WANDER_D_THETA5_000_MRAD,
                                       "outward_from_mm": OUTWARD_FROM_000_MM,
                                       "round_tries": ROUND_TRIES_000,
                                       "outward_inward_mrad": OUTWARD_INWARD_000_MRAD,
                                       "edge_mm": EDGE_000_MM}}
    detectors = {"SEARCH": ("radial_symbol", "radial_cut"), "APPROACH": ("radial_symbol",),
                 "ADJUST": ("dual_plus", "radial_symbol"), "PRECISE_GRASP": ("spoke",),
                 # LIFT: the grasp check (grasp.py): the held object fills the frame, the
                 # object seen standing away is a miss
                 "LIFT": ("dual_plus", "radial_symbol", "held_fill")}
    # ADJUST closes in on the dual "+" and reads the rings only when the "+" are not seen
    detector_fallbacks = {"ADJUST": {"radial_symbol": "dual_plus"},
                          "SEARCH": {"radial_cut": "radial_symbol"}}  # cut: not read whole
    search_detector = "radial_symbol"
    adjust_detector = "dual_plus"
    check_detectors = ("dual_plus", "radial_symbol")
    held_colour = "body_brown"  # the post's brown body (docs/markers.md)
    object_detectors = ("dual_plus", "radial_symbol")  # both are on the object's top
    grasp_alpha_mrad = kinematics.ALPHA_DOWN_MRAD
    keeps_sightings = True
    # ADJUST from the search posture: eq. (10) with the scenario's gains (000 §IV: k_theta2 = 1,
    # k_theta3 = k_theta4 = 0, theta2 alone) moves the joints, no jump on entry
    adjust_keeps_posture = True
    # from the search posture the "+" pair lies along the view: at the detector's one depth it
    # comes out ~21 mm apart (refused), on the top's plane 47.3 mm, and the hover goes over one
    plus_on_top = True

    # --- SEARCH --------------------------------------------------------------------------------
    def found(self, t: Task, now: int, inp: TaskInputs, name: str, det: RadialSymbol) -> bool:
        return t.see_object(now, inp, name, det)

    def found_why(self, t: Task) -> str:
        return f"radial symbol seen, object at {t.obj} mm"

    def lost_search(self, t: Task, sp: SearchParams, lost_in: str
                    ) -> tuple[SearchParams, int, int]:
        """Lost near the object (ADJUST, PRECISE_GRASP): "the mobile platform has to stop
        until the object is seen again" and the arm searches by Fig. 5 (000 §III.B.2, §III.C),
        theta2 in steps of the paper's d_theta2 from where the camera looked: theta2s gives the
        camera pitch alpha it had, in the search posture (from the grasp's look straight down,
        theta2_min)."""
        alpha = t.arm[2] + t.arm[3] + t.arm[4]
        th2s = min(max(alpha - sp.theta3_mrad - sp.theta4_mrad, sp.theta2_min_mrad),
                   sp.theta2_max_mrad)
        return replace(sp, dense_cycles=max(1, sp.dense_cycles)), th2s, t.arm[5]

    # SEARCH's back-off from a cut symbol: at most back_offs_max a run (search_back_off)
    back_offs_max = BACK_OFFS_000

    def search_back_off(self, t: Task, now: int, inp: TaskInputs, dets: dict) -> bool:
        """The radial symbol cut by the frame's border: too near to be read. Turn toward it
        (the waist of the frame's pose, and the border's half field of view beyond it), move
        off it (:meth:`back_off_move`), stand until a frame taken after the stop has come, and
        search again from there (a new look-around: the symbol is then ahead, in range). At
        most ``back_offs_max`` a run, where :meth:`back_off_here` allows it. True while the
        back-off takes the step."""
        ms = t.ms
        if ms.back_off is None:
            cut = dets.get("radial_cut")
            if not isinstance(cut, registry.row("radial_cut").result_type()):
                return False
            # its bearing (right positive, as the waist's) at the border it is cut at; the base
            # turns left positive
            half_fov = atan2_mrad(t.cam.u0_px, t.cam.f_px)
            turn = -(t.arm_at(now - t.p.frame_latency_us)[5] + cut.side * half_fov)
            if cut.y + cut.h >= 2 * t.cam.v0_px and CUT_LOOK_FLAT * cut.h <= cut.w:  # near
                ms.cut_seen_us, ms.cut_heading_mrad = now, wrap_mrad(inp.heading_mrad + turn)
            if ms.back_offs >= self.back_offs_max \
                    or t.confirm_until is not None or not self.back_off_here(t, inp) \
                    or not self.back_off_due(t, now):
                return False
            ms.back_offs += 1
            ms.back_off = self.back_off_first(t, inp, turn)
            t.note(back_off={"side": cut.side, "turn_mrad": turn, "n": ms.back_offs})
        if self.back_off_move(t, now, inp):
            return True
        t.wheels = (0, 0)
        if not dets or now - t.p.frame_latency_us < ms.back_off[1]:
            return True
        ms.back_off = None
        t.search = ArmSearch(SearchParams(**t.p.search), t.arm[2], t.arm[5], now)
        t.turn_from = t.wander_from = t.wander_round = t.wander_look = None
        return False

    # SEARCH's look after a leg stopped within this long of a cut frame (0: never)
    cut_look_us = CUT_LOOK_000_US

    def search_cut_look(self, t: Task, now: int) -> int | None:
        """A frame showed the symbol cut within ``cut_look_us``: the obstacle that stopped the
        leg may be the object, too near for the sweep's far level but beyond the symbol's near
        limit (0.45 m from the camera): facing where it was seen, a cycle at rest reads it."""
        if self.cut_look_us > 0 and t.ms.cut_seen_us is not None \
                and now - t.ms.cut_seen_us <= self.cut_look_us:
            return t.ms.cut_heading_mrad
        return None

    def back_off_here(self, t: Task, inp: TaskInputs) -> bool:
        """000: only from the run's start (within BACK_OFF_FROM_MM of the odometry's origin,
        before any loss): its back-off drives backward, where the sonar ring does not look,
        and only the start is known clear."""
        return not t.counters["lost"] \
            and inp.x_mm * inp.x_mm + inp.y_mm * inp.y_mm <= BACK_OFF_FROM_MM ** 2

    def back_off_due(self, t: Task, now: int) -> bool:
        """A frame shows the cut symbol where the back-off may be made: it is made now (000: at
        the first such frame)."""
        return True

    def back_off_first(self, t: Task, inp: TaskInputs, turn: int) -> tuple:
        """The back-off's first phase, ``turn`` mrad (left positive) facing the symbol: 000
        turns on the spot toward it (then backs straight off, :meth:`back_off_move`)."""
        return ("turn", inp.heading_mrad, turn)

    def back_off_move(self, t: Task, now: int, inp: TaskInputs) -> bool:
        """One step of the back-off's move (True while it moves); over, ``t.ms.back_off`` is
        ("look", stopped_us, 0). 000: the turn toward the symbol, then straight back
        BACK_OFF_000_MM at slow_mmps."""
        ms = t.ms
        phase, a, b = ms.back_off
        if phase == "turn":
            if abs(wrap_mrad(inp.heading_mrad - a)) < abs(b):
                t.wheels = turn_in_place(1 if b > 0 else -1, t.p.turn_wheel_mmps)
                return True
            phase, a, b = ms.back_off = ("back", inp.x_mm, inp.y_mm)
        if phase == "back":
            dx, dy = inp.x_mm - a, inp.y_mm - b
            if dx * dx + dy * dy < BACK_OFF_000_MM * BACK_OFF_000_MM:
                t.wheels = (-t.p.slow_mmps, -t.p.slow_mmps)
                return True
            ms.back_off = ("look", now, 0)
        return False

    def grasp_lost(self, t: Task, now: int, waited_us: int) -> bool:
        """No spoke under the camera at the hover: the object is lost during the grasp (000
        §III.C: "the object searching when lost is similar to ... Fig. 5"). The first time in a
        run, search for it (:meth:`lost_search`), then approach and grasp again; after that, go
        down on the rough position (the ``no_spoke`` fallback)."""
        if t.ms.grasp_searches >= 1:
            return False
        t.ms.grasp_searches += 1
        t.lost_in = "PRECISE_GRASP"
        t.go(now, "LOST", f"no spoke seen for {waited_us} us at the hover: object lost "
             f"during the grasp")
        return True

    # --- APPROACH: the path of eq. (9) ---------------------------------------------------------
    def enter_approach(self, t: Task, now: int, inp: TaskInputs) -> None:
        pass

    def plan(self, t: Task, now: int, inp: TaskInputs
             ) -> tuple[PathFollower | None, OpCounts, dict]:
        pp = Params000(**{"standoff_m": t.p.approach_standoff_mm / 1000, **t.p.planner})
        return plan_follower(now, inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps, t.obj, pp)

    def sighting_usable(self, t: Task, now: int, inp: TaskInputs) -> bool:
        return True

    def sonar_replan(self, t: Task, now: int, inp: TaskInputs, moved: bool) -> bool | None:
        return None  # 000 plans once (again when the estimate moves); no sonar check

    def hold_before_plan(self, t: Task, now: int, inp: TaskInputs) -> bool:
        return False

    def way_blocked(self, t: Task, inp: TaskInputs, dist_mm: int) -> bool:
        return False

    def start_detour(self, t: Task, inp: TaskInputs) -> bool:
        return False

    def path_wheels(self, cmd: WheelCommand) -> tuple[int, int]:
        return cmd.left_mm_s, cmd.right_mm_s

    # --- ADJUST --------------------------------------------------------------------------------
    def adjust_done(self, t: Task, now: int, det: DualPlus, dist_mm: int) -> bool:
        return False  # the close approach decides (adjust.py)

    def adjust_vmax_mmps(self, p: TaskParams) -> int:
        return p.adjust_vmax_mmps

    # --- the arm -------------------------------------------------------------------------------
    def look_height_mm(self, p: TaskParams, top: bool) -> int:
        return p.object_top_mm if top else p.grasp_height_mm

    def grasp_ik(self, geom: ArmGeometry, target_q4: tuple[int, int, int]
                 ) -> ArmPose | Unreachable:
        """Gripper down, eq. (11) of 000."""
        return kinematics.ik_rough_grasp_000(geom, target_q4)

    def rough_target(self, t: Task, inp: TaskInputs) -> tuple[int, int, int]:
        """``hover_mm`` above the object top; over the nearer "+" when both are known, the
        grasp itself on the axis (``grasp_xy_q4``)."""
        target = GRASP.object_target_q4(t, inp, t.p.object_top_mm + t.p.hover_mm)
        t.grasp_xy_q4 = target[:2]
        if t.plus_odom is not None:  # hover over the nearer "+", grasp on the axis
            pts = [odom_to_platform_q4(inp.x_mm, inp.y_mm, inp.heading_mrad,
                                       t.p.mount_forward_mm, *q) for q in t.plus_odom]
            near = min(pts, key=lambda q: q[0] * q[0] + q[1] * q[1])
            target = (near[0], near[1], target[2])
        return target

    def lowers_hover(self) -> bool:
        return True

    def enter_precise(self, t: Task, now: int, inp: TaskInputs) -> None:
        """Roll the wrist to pi/2 (000 §III.C.2), then align on the spoke."""
        t.set_arm(now, *t.arm[2:6], th1=kinematics.ROLL_PRECISE_MRAD)
        t.phase = "roll"
        t.roll_scan = 0


RULES = Method000()
