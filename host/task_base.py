"""Bookkeeping shared by the task's states (host.task): arm targets and their settle time, the
history of arm targets and base poses (a detection describes the frame captured
``frame_latency_us`` ago), the object estimate in the odometry frame, the posture adjustment
toward it (eq. (10) of 000) and the IK of the grasp.  A mixin of :class:`mobigrasp.host.task.Task`.
"""

from __future__ import annotations

from mobigrasp.host import arm_calib, kinematics
from mobigrasp.host.fixedpoint import isqrt
from mobigrasp.host.posture import PostureParams, adjust_posture
from mobigrasp.host.task_sense import (
    object_in_platform,
    odom_to_platform_q4,
    platform_to_odom_mm,
    plus_positions,
)

GRASP_ALPHAS_002 = (0, -100, -200, -280)  # horizontal first; the world accepts |alpha| < 0.3


class TaskBase:
    """Helpers of the state handlers (host.task_states, host.task_grasp)."""
    def run_state(self, now: int, inp, dets: dict) -> None:
        if self.entry_pending:
            self.entry_pending = False
            state = self.state
            getattr(self, f"enter_{state}", lambda n, i: None)(now, inp)
            if self.state != state:
                return
        getattr(self, f"do_{self.state}")(now, inp, dets)

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

    def see_object(self, now: int, inp, name: str, det) -> bool:
        """Update the object estimate from a detection; False if unusable (counted)."""
        t_cap = now - self.p.frame_latency_us
        if t_cap < self.trust_from_us:
            return False  # captured while the arm swung to a new posture: pose unknown
        joints = self._at(self.arm_hist, t_cap)[1] if self.arm_hist else tuple(self.arm)
        _, x, y, h = self._at(self.pose_hist, t_cap) if self.pose_hist else (
            0, inp.x_mm, inp.y_mm, inp.heading_mrad)
        try:
            p = object_in_platform(name, det, self.geom, joints, self.cam)
        except (ValueError, TypeError, ZeroDivisionError):
            self.counters["bad_detections"] += 1
            return False
        if p is None or isqrt(p[0] * p[0] + p[1] * p[1]) > 5000 * 16:
            self.counters["bad_detections"] += 1
            return False
        self.obj = platform_to_odom_mm(x, y, h, self.p.mount_forward_mm, p)
        self.obj_seen_us = now
        if name == "dual_plus":
            self._remember_plus(det, joints, (x, y, h))
        return True

    def _remember_plus(self, det, joints: tuple, pose: tuple) -> None:
        """Keep both "+" in the odometry frame: the precise grasp looks at one of them (000:
        "only a '+' symbol is used in the precise grasping")."""
        try:
            pair = plus_positions(det, self.geom, joints, self.cam)
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
        look_mm = self.p.object_top_mm if top else self.p.grasp_height_mm
        if self.method == "002" and top:
            look_mm //= 2  # the two rings sit at mid-height: keep them, not the top, in view
        z = (look_mm - self.p.h_shoulder_mm) * 16
        adj = adjust_posture(self.geom, tuple(self.arm[2:6]), (x, y, z), self.posture_params())
        self.arm[2:6] = [adj.theta2_mrad, adj.theta3_mrad, adj.theta4_mrad, adj.theta5_mrad]

    def posture_params(self, max_step_mrad: int | None = None) -> PostureParams:
        """The task's posture parameters (``self.p.posture`` with the step cap, by default
        ``posture_step_mrad``); built once per TaskParams and cap, not at every control step."""
        cap = self.p.posture_step_mrad if max_step_mrad is None else max_step_mrad
        if getattr(self, "_pp_of", None) is not self.p:  # first call, or new TaskParams
            self._pp_of, self._pp_by_cap = self.p, {}
        pp = self._pp_by_cap.get(cap)
        if pp is None:
            pp = self._pp_by_cap[cap] = PostureParams(**{"max_step_mrad": cap,
                                                         **self.p.posture})
        return pp

    def gripper_point_q4(self) -> tuple[int, int, int]:
        return kinematics.fk_mm_q4(self.geom, *self.arm[2:6])

    def grasp_ik(self, target_q4: tuple[int, int, int], alpha: int | None = None):
        """IK for the method: 000/001 gripper down (eq. (11)); 002 horizontal (eq. (4)) first."""
        if alpha is not None:
            return kinematics.ik_pitch_mm_q4(self.geom, target_q4, alpha)
        if self.method != "002":
            return kinematics.ik_rough_grasp_000(self.geom, target_q4)
        first = None
        for a in GRASP_ALPHAS_002:
            res = kinematics.ik_pitch_mm_q4(self.geom, target_q4, a)
            if isinstance(res, kinematics.ArmPose):
                return res
            first = first or res
        return first

    def apply_pose(self, now: int, pose, th1: int | None = None) -> None:
        self.set_arm(now, pose.theta2_mrad, pose.theta3_mrad, pose.theta4_mrad,
                     pose.theta5_mrad, th1)
