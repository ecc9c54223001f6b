"""APPROACH: the common entry, and the path approach of 000 and 001.

000 / 001 follow the best Bezier path (host.planning, host.control.path_follow) while the
posture adjustment (host.posture, eq. (10) of 000) keeps the object in view from the odometry
estimate; at the path's end (or near the object) ADJUST takes over (000), or the grasp from the
grasp circle (001, method001.py ``path_end``). The planner and what the sonars add (001's
replanning of §III.E, its detours) are the method's (:class:`PathMethod`, method000.py and
method001.py); 002 approaches with its fuzzy controller instead (method002.py). Each handler
takes the task ``t`` first.
"""

from __future__ import annotations

from abc import abstractmethod
from typing import Any

from mobigrasp.host.fixedpoint import atan2_mrad, isqrt
from mobigrasp.host.planning.anytime import PlanJob
from mobigrasp.host.task.drive import make_pose, turn_in_place
from mobigrasp.host.task.method import Method


class ApproachStates:
    """APPROACH: its entry action and step (the method's), and the path approach."""

    def enter_APPROACH(self, t, now: int, inp) -> None:
        t.follower, t.plan_attempts, t.plan_job = None, 0, None
        t.rules.enter_approach(t, now, inp)

    def do_APPROACH(self, t, now: int, inp, dets: dict) -> None:
        t.rules.approach(t, now, inp, dets)

    def follow_path(self, t, now: int, inp, dets: dict) -> None:
        """One step of the path approach (000 §III.B.1, 001 §III)."""
        rules = t.rules
        det = dets.get("radial_symbol")
        if det is not None and rules.sighting_usable(t, now, inp):
            t.see_object(now, inp, "radial_symbol", det)
        if t.plan_job is not None:  # planning in slices (host/planning/anytime.py)
            if not self._plan_slice(t, now, inp):
                return  # not done: the old path or a standstill meanwhile
            if t.state != "APPROACH" or t.follower is None:
                t.wheels = (0, 0)
                return
        moved = (t.plan_obj is not None and isqrt((t.obj[0] - t.plan_obj[0]) ** 2 + (
            t.obj[1] - t.plan_obj[1]) ** 2) > t.p.replan_shift_mm)
        replan = rules.sonar_replan(t, now, inp, moved)
        if replan is not None:
            if replan:
                return
        elif t.follower is None or moved:
            if rules.hold_before_plan(t, now, inp):
                return
            if t.follower is None and t.plan_attempts and not self._face_object(t, inp):
                return  # no feasible curve from here: face the object in place, then replan
            self._plan(t, now, inp)
            if t.plan_job is not None:
                return  # its slices go on in the next steps
            if t.state != "APPROACH" or t.follower is None:
                t.wheels = (0, 0)
                return
        t.look_at_object(inp)
        x, y = t.obj_platform(inp)
        dist = isqrt(x * x + y * y) // 16
        cmd = self._follow(t, now, inp)
        if cmd.done or dist <= t.p.grasp_r_mm + rules.near_margin_mm or _object_at_footprint(
                t, inp, rules.object_clear_mm):
            rules.path_end(t, now, inp, path_end_why(cmd.error_mm, dist), cmd.error_mm)

    @staticmethod
    def _follow(t, now: int, inp):
        """The follower's command for the present pose, its wheels by the method, and the
        method's count of this step along the path charged (``PathMethod.follow_ops``)."""
        cmd = t.follower.step(now, make_pose(inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps))
        t.wheels = t.rules.path_wheels(cmd)
        if t.rules.follow_ops is not None:
            t.charge(t.rules.follow_ops)
        return cmd

    def _plan_slice(self, t, now: int, inp) -> bool:
        """Charge this step's slice of the plan being made; True once it is done (its path
        installed, starting now, or its failure handled), False while it is still computed."""
        job = t.plan_job
        t.charge(job.step())
        if not job.done:
            if t.follower is not None:  # the old path meanwhile
                t.look_at_object(inp)
                self._follow(t, now, inp)
            else:
                t.wheels = (0, 0)
            return False
        t.plan_job = None
        if job.follower is not None:
            t.follower = t.rules.start_path(t, job.follower, now)
        elif job.detail is not None:
            self._plan_failed(t, now, inp, job.detail)
        return True

    def _plan(self, t, now: int, inp) -> None:
        follower, ops, detail = t.rules.plan(t, now, inp)
        t.counters["plans"] += 1
        t.note(plan=detail)
        t.plan_us, t.plan_obj = now, t.obj
        t.plan_job = PlanJob.start(follower, detail, ops)
        self._plan_slice(t, now, inp)

    def _plan_failed(self, t, now: int, inp, detail: dict) -> None:
        """No path from the plan: already there, fewer attempts, the direct approach, a
        detour, or a failure."""
        rules = t.rules
        if "already" in detail["reason"]:
            rules.path_end(t, now, inp, f"no path needed: {detail['reason']}", None)
            return
        t.plan_attempts += 1
        if t.plan_attempts >= t.p.max_plan_attempts:
            x, y = t.obj_platform(inp)
            dist = isqrt(x * x + y * y) // 16
            if dist <= t.p.direct_max_mm and not rules.way_blocked(t, inp, dist):
                # the close approach can do it
                t.go(now, "ADJUST", f"no feasible curve ({detail['reason']}); object "
                     f"{dist} mm away: direct approach")
            elif rules.start_detour(t, inp):
                t.plan_attempts, t.follower = 0, None
            else:  # not straight into something in the way (docs/cosim.md "Measured", T4)
                t.fail(now, f"no feasible approach path: {detail['reason']}")

    def _face_object(self, t, inp) -> bool:
        """Turn the base in place toward the object; True once it faces it (ours, not the
        papers': a curve from a standstill facing away can violate A_max or R_min)."""
        x, y = t.obj_platform(inp)
        bearing = atan2_mrad(x, y + t.p.mount_forward_mm * 16)  # seen from the axle
        if abs(bearing) <= t.p.bearing_tol_mrad:
            t.wheels = (0, 0)
            return True
        t.wheels = turn_in_place(-1 if bearing > 0 else 1, t.p.turn_wheel_mmps)
        return False


PATH = ApproachStates()


class PathMethod(Method):
    """A method whose APPROACH follows a planned path (000, 001): the hooks of
    :meth:`ApproachStates.follow_path`."""

    # the path ends early with the object this much beyond ADJUST's goal (``grasp_r_mm``)
    near_margin_mm = 100
    # and, when not 0, with the object (by the estimate) within this much of the footprint
    # once the base has braked (:func:`_object_at_footprint`)
    object_clear_mm = 0
    # the work of a step along the path (the look at the object, the follower's step, the
    # distance checks) charged each step, as the plans' counts are; None: not charged (000:
    # its traces are kept as they are, docs/budget.md "The control step's charge")
    follow_ops: Any = None

    def approach(self, t: Any, now: int, inp: Any, dets: dict) -> None:
        PATH.follow_path(t, now, inp, dets)

    @abstractmethod
    def plan(self, t: Any, now: int, inp: Any) -> tuple[Any, Any, dict]:
        """Plan from the present pose toward ``t.obj``: (follower or None, ops, trace detail
        with at least ``reason``)."""

    def start_path(self, t: Any, follower: Any, now: int) -> Any:
        """The planned path's time starts now, in the step of its plan's last slice
        (host/planning/anytime.py)."""
        follower.start_us = now
        return follower

    @abstractmethod
    def sighting_usable(self, t: Any, now: int, inp: Any) -> bool:
        """This step's radial symbol may update the object estimate."""

    @abstractmethod
    def sonar_replan(self, t: Any, now: int, inp: Any, moved: bool) -> bool | None:
        """The sonar check of the path being followed: None when none is due; else True when
        the step ends here (the base stopped), False to follow on."""

    @abstractmethod
    def hold_before_plan(self, t: Any, now: int, inp: Any) -> bool:
        """Do something else than plan in this step (True: the wheels are set)."""

    @abstractmethod
    def way_blocked(self, t: Any, inp: Any, dist_mm: int) -> bool:
        """With no feasible curve: the straight close approach toward the object
        ``dist_mm`` away is blocked."""

    @abstractmethod
    def start_detour(self, t: Any, inp: Any) -> bool:
        """With no feasible curve and no direct approach: start a drive aside (True) or not."""

    @abstractmethod
    def path_wheels(self, cmd: Any) -> tuple[int, int]:
        """Wheel speeds from the path follower's command."""

    def path_end(self, t: Any, now: int, inp: Any, why: str, error_mm: int | None) -> None:
        """The path followed to its end (the follower's ``error_mm`` there), the object near,
        or no path needed (``error_mm`` None), for the reason ``why``: 000's vision-based
        adjustment (§III.B) from here."""
        t.go(now, "ADJUST", why)


# the base's travel after its wheels are set to 0: the motors' lag (tau 0.1 s) and the command's
# way to the wheels, ~31 mm from 205 mm/s (docs/task.md "001's grasp")
BRAKE_MS = 150


def _object_at_footprint(t: Any, inp: Any, clear_mm: int) -> bool:
    """The object's estimate within ``clear_mm`` of the footprint (its radius
    ``sonar_offset_mm``) once the base, stopped now, has braked (``BRAKE_MS`` at its speed);
    ``clear_mm`` 0: not checked."""
    if not clear_mm:
        return False
    axle_mm = isqrt((t.obj[0] - inp.x_mm) ** 2 + (t.obj[1] - inp.y_mm) ** 2)
    brake_mm = max(0, inp.v_mmps) * BRAKE_MS // 1000
    return axle_mm - brake_mm <= t.p.sonar_offset_mm + clear_mm


def path_end_why(error_mm: int, dist_mm: int) -> str:
    """The reason of APPROACH's transition at the path's end."""
    return f"path followed (error {error_mm} mm), object {dist_mm} mm from the waist"
