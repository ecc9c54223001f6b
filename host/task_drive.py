"""How the task moves the base: approach planning and following, the close approach, fuzzy.

Each function is the one place the task calls another helper's code (host.planning,
host.control), so a change of API is a change here only:

- :func:`plan_follower` calls the Bezier planner of 000 (eq. (9)) or 001 (eq. (17)) and wraps the
  chosen curve in host.control.path_follow's integer :class:`PathFollower` (eq. (8) feed-forward
  plus Kanayama feedback).  The planning ops (soft-float) are returned for the ARM9 budget.
- :func:`close_in` is the close approach of 000 (vision-based approaching adjustment, §III.B):
  integer proportional law driving until the object is ``grasp_r_mm`` ahead of the waist axis
  and straight ahead; facing the object first, since turning in place swings the waist sideways.
- :func:`make_fuzzy` builds 002's fuzzy approach (host.control.fuzzy: 35 rules, eq. (1) centroid,
  eq. (2) wheel law, stop at d_pixel > T_d).

Wheel speeds are (left, right) mm/s, positive forward; counter-clockwise turns have right > left.
"""

from __future__ import annotations

from typing import Any

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.control.fuzzy import FuzzyApproach, FuzzyParams
from mobigrasp.host.control.path_follow import PathFollower, Trajectory, wheel_speeds
from mobigrasp.host.fixedpoint import atan2_mrad, cos_q12, isqrt, sin_q12
from mobigrasp.host.odometry import Pose

# The planners are imported with this module, not at the first plan: an import inside a control
# step stalled that one tick by ~30 ms of host CPU (more where no bytecode is cached), and the rig
# waits for every tick's DONE. Nothing modelled depends on when a module is loaded.
from mobigrasp.host.planning.bezier000 import Params000, plan_000
from mobigrasp.host.planning.bezier001 import Params001, is_object_echo, plan_001
from mobigrasp.host.planning.escape import escape_heading, segment_clear
from mobigrasp.host.planning.replan import Replanner
from mobigrasp.host.planning.sonar_regions import SonarConfig, infeasible_regions

MAX_TRACE_CANDIDATES = 40  # candidate curves kept in the trace for the plots (evenly picked)
ARC_BOUND_001 = True  # 001: eq. (16) wedges cut to the grown echo arc (planner_params_001)
DETOUR_EXTRA_MM = 100  # 001: a detour's way out is checked this much beyond its end (stopping)
DETOUR_MARGIN_MM = 100  # ... against the infeasible regions grown by this: it drives open-loop


def make_pose(x_mm: int, y_mm: int, heading_mrad: int, v_mmps: int) -> Pose:
    """An odometry Pose from the task's inputs (mm, mrad, mm/s)."""
    return Pose(int(x_mm) * 1000, int(y_mm) * 1000, int(heading_mrad), int(v_mmps), 0)


def plan_follower(method: str, now_us: int, x_mm: int, y_mm: int, heading_mrad: int,
                  v_mmps: int, obj_xy_mm: tuple[int, int], sonar_mm: tuple,
                  planner_params: Any = None, v_limit_mmps: int | None = None
                  ) -> tuple[PathFollower | None, OpCounts, dict]:
    """Plan with 000's or 001's planner from the pose toward the object; (follower, ops, detail).

    ``detail`` holds what the trace needs for the plots: candidate count, feasible count, the
    reason, the chosen control points and the modelled ARM9 time of the plan."""

    h = heading_mrad / 1000.0
    c, s = cos_q12(heading_mrad), sin_q12(heading_mrad)
    start = (x_mm / 1000.0, y_mm / 1000.0)
    vel = (v_mmps * c / 4096 / 1000.0, v_mmps * s / 4096 / 1000.0)
    target = (obj_xy_mm[0] / 1000.0, obj_xy_mm[1] / 1000.0)
    if method == "001":
        p = planner_params if planner_params is not None else Params001()
        plan = plan_001(start, vel, h, target, [int(v) for v in sonar_mm], p)
    else:
        p = planner_params if planner_params is not None else Params000()
        plan = plan_000(start, vel, target, p, heading_rad=h)
    n_feasible = sum(1 for cand in plan.candidates if cand.feasible)
    step = max(1, len(plan.candidates) // MAX_TRACE_CANDIDATES)
    cands = [[list(map(float, row)) for row in plan.candidates[i].curve.ctrl]
             for i in range(0, len(plan.candidates), step)]
    detail: dict = {"planner": method, "reason": plan.reason,
                    "candidates": len(plan.candidates), "feasible": n_feasible,
                    "plan_arm9_us": plan.ops.time_us(), "candidates_ctrl": cands}
    if plan.best is None:
        return None, plan.ops, detail
    traj = Trajectory.from_curve(plan.best)
    limit = v_limit_mmps if v_limit_mmps is not None else int(round(p.v_max * 1000))
    detail["best_ctrl"] = [list(map(float, row)) for row in plan.best.ctrl]
    detail["duration_us"] = traj.duration_us
    return PathFollower(traj, now_us, limit), plan.ops + traj.ops, detail


def close_in(obj_platform_q4: tuple[int, int], grasp_r_mm: int, tol_mm: int,
             bearing_tol_mrad: int, vmax_mmps: int) -> tuple[tuple[int, int], bool, dict]:
    """Close approach toward an object at platform (X_r, Y_r) Q4 mm: (wheels, done, detail)."""
    xr, yr = obj_platform_q4
    bearing = atan2_mrad(xr, yr)  # right positive, as theta5
    dist = isqrt(xr * xr + yr * yr) // 16
    err = dist - grasp_r_mm
    detail = {"dist_mm": dist, "bearing_mrad": bearing, "err_mm": err}
    if abs(err) <= tol_mm and abs(bearing) <= bearing_tol_mrad:
        return (0, 0), True, detail
    v = max(-vmax_mmps, min(vmax_mmps, 2 * err))
    if abs(bearing) > 4 * bearing_tol_mrad:
        v = 0  # face the object first
    omega = -2 * bearing  # object to the right -> turn clockwise (negative yaw rate)
    return wheel_speeds(v, omega, vmax_mmps), False, detail


def turn_in_place(direction: int, wheel_mmps: int) -> tuple[int, int]:
    """Wheels turning the base on the spot: direction +1 counter-clockwise, -1 clockwise."""
    return (-direction * wheel_mmps, direction * wheel_mmps)


def make_fuzzy(params: FuzzyParams | None = None) -> FuzzyApproach:
    """002's fuzzy approach controller (host.control.fuzzy)."""
    return FuzzyApproach(params if params is not None else FuzzyParams())


def _state_m(x_mm: int, y_mm: int, heading_mrad: int, v_mmps: int):
    c, s = cos_q12(heading_mrad), sin_q12(heading_mrad)
    return ((x_mm / 1000.0, y_mm / 1000.0), heading_mrad / 1000.0,
            (v_mmps * c / 4096 / 1000.0, v_mmps * s / 4096 / 1000.0))


def _follower(curve, now_us: int, v_limit_mmps: int) -> tuple[PathFollower, OpCounts]:
    traj = Trajectory.from_curve(curve)
    return PathFollower(traj, now_us, v_limit_mmps), traj.ops


def planner_params_001(task_params) -> Any:
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
    sonar = SonarConfig(sensor_offset_m=task_params.sonar_offset_mm / 1000.0,
                        shared_echo_tol_m=tol / 1000.0 if tol > 0 else None,
                        arc_angle_bound=ARC_BOUND_001)
    return Params001(**{"sonar": sonar, **task_params.planner})


def start_001(now_us: int, x_mm: int, y_mm: int, heading_mrad: int, v_mmps: int,
              obj_xy_mm: tuple[int, int], sonar_mm: tuple, params=None):
    """001's first plan through host.planning.replan.Replanner (which then watches the sonars):
    (replanner, follower or None, ops, detail)."""

    p = params if params is not None else Params001()
    rp = Replanner((obj_xy_mm[0] / 1000.0, obj_xy_mm[1] / 1000.0), p)
    pos, h, vel = _state_m(x_mm, y_mm, heading_mrad, v_mmps)
    plan = rp.start(now_us, pos, h, vel, [int(v) for v in sonar_mm])
    detail = {"planner": "001", "reason": plan.reason, "candidates": len(plan.candidates),
              "feasible": sum(1 for c in plan.candidates if c.feasible),
              "plan_arm9_us": plan.ops.time_us()}
    if plan.best is None:
        return rp, None, plan.ops, detail
    follower, ops = _follower(plan.best, now_us, int(round(p.v_max * 1000)))
    detail["best_ctrl"] = [list(map(float, row)) for row in plan.best.ctrl]
    return rp, follower, plan.ops + ops, detail


def escape_001(rp, x_mm: int, y_mm: int, heading_mrad: int, sonar_mm: tuple,
               obj_xy_mm: tuple[int, int], detour_mm: int, side: int = 0):
    """001 detour heading (host.planning.escape): the direction nearest the object's bearing
    whose straight ``detour_mm`` + DETOUR_EXTRA_MM stays out of the infeasible regions (eq.
    (16)) of the present reading and of the replanner's memory, grown by DETOUR_MARGIN_MM;
    ``side`` as in host.planning.escape.escape_heading. (heading_mrad or None, ops)"""
    length_mm, margin_mm = detour_mm + DETOUR_EXTRA_MM, DETOUR_MARGIN_MM

    pos, h, _ = _state_m(x_mm, y_mm, heading_mrad, 0)
    p = rp.params
    scan = infeasible_regions(p.sonar, pos, h, [int(v) for v in sonar_mm])
    regions = [r for r in scan.regions if not is_object_echo(r, rp.target, p.object_echo_tol_m)]
    goal = atan2_mrad(obj_xy_mm[1] - y_mm, obj_xy_mm[0] - x_mm) / 1000.0
    head, ops = escape_heading(regions + list(rp.memory), pos, h, goal, length_mm / 1000.0,
                               margin_mm / 1000.0, side=side)
    return (None if head is None else int(round(head * 1000))), ops


def straight_clear_001(rp, x_mm: int, y_mm: int, heading_mrad: int, sonar_mm: tuple,
                       obj_xy_mm: tuple[int, int], travel_mm: int):
    """001: does the straight drive of ``travel_mm`` toward the object (the close approach of
    000 §III.B, which has no obstacle test of its own) stay out of the infeasible regions (eq.
    (16)) of the present reading and of the replanner's memory? (clear, ops)"""

    pos, h, _ = _state_m(x_mm, y_mm, heading_mrad, 0)
    p = rp.params
    scan = infeasible_regions(p.sonar, pos, h, [int(v) for v in sonar_mm])
    regions = [r for r in scan.regions if not is_object_echo(r, rp.target, p.object_echo_tol_m)]
    toward = atan2_mrad(obj_xy_mm[1] - y_mm, obj_xy_mm[0] - x_mm) / 1000.0
    return segment_clear(regions + list(rp.memory), pos, toward, max(0, travel_mm) / 1000.0)


def update_001(rp, now_us: int, x_mm: int, y_mm: int, heading_mrad: int, v_mmps: int,
               sonar_mm: tuple):
    """001 §III.E: check the rest of the path against fresh sonar, replan when blocked.
    Returns (decision, new follower or None, ops)."""
    pos, h, vel = _state_m(x_mm, y_mm, heading_mrad, v_mmps)
    dec = rp.update(now_us, pos, h, vel, [int(v) for v in sonar_mm])
    if not dec.replanned or dec.curve is None:
        return dec, None, dec.ops
    follower, ops = _follower(dec.curve, now_us, int(round(rp.params.v_max * 1000)))
    return dec, follower, dec.ops + ops
