"""Grasp states of the task: ROUGH_GRASP, PRECISE_GRASP and LIFT (000 §III.C, 002 §4).

A mixin of host.task.Task (through host.task_states).  Targets in the platform frame, Q4 mm:

- ROUGH_GRASP (000 §III.C.1): the gripper above the object top by ``hover_mm``, pitched
  alpha_T = -pi/2, by eq. (11) of 000 (host.kinematics).  002: the pre-grasp point
  ``pregrasp_back_mm`` short of the cylinder axis at the grasp height, horizontal gripper by
  eq. (4) of 002 (tilting down to -0.28 rad if the level pose is outside the joint limits).
- PRECISE_GRASP (000 §III.C.2): roll theta1 to pi/2, then on each spoke reading turn
  until k_T = 0 and move up/down until w_T is in [20, 40] px; then down to the grasp height and
  close.  The turn is made with the wrist roll by default (``precise_align_ch`` = 1): with the
  gripper vertical it turns the image like the waist does, but does not swing the gripper
  sideways by r * d_theta5 (20 mm at r = 140 mm for 0.15 rad, more than the grasp tolerance);
  ``precise_align_ch`` = 5 turns the waist as the brief reads 000.  No spoke for
  ``spoke_wait_us`` (or too many steps): go down on the rough position and say so in the trace.
  002: move in from the pre-grasp point to the axis and close; the pitch is chosen again there
  (level first), since with theta2 <= 0 the pre-grasp point may be reachable only tilted.
- LIFT: raise by ``lift_mm`` with the same pitch, then the grasp check (ours: the papers end at
  the closed gripper, and the host has no finger sensor, FLAG_GRIPPER_CLOSED only says the close
  was commanded): the camera swings back and up to look down at the place the object stood
  (``CHECK_VIEWS``, eq. (11) of 000; then eq. (10) keeps it in view); a held object has left
  it (it hangs under the gripper, behind that view), a missed one still stands there.  The
  object's marker (dual "+" or radial symbol, 002 the red cylinder) seen in
  ``CHECK_SEEN_FRAMES`` frames standing away from the fingertip (while the arm rises, or while
  the waist turns the view about the place, ``CHECK_WAIST_MRAD``) means a miss: open, ADJUST
  from the new sighting and grasp again (up to ``MAX_REGRASPS`` times, then FAILED); otherwise
  DONE.  Random 001 seeds 5001 and 5017 closed the gripper 37 mm beside the object and
  reported DONE.
"""

from __future__ import annotations

from mobigrasp.host import arm_calib, kinematics
from mobigrasp.host.fixedpoint import atan2_mrad, cos_q12, isqrt, sin_q12
from mobigrasp.host.search import SearchParams
from mobigrasp.host.task_base import TaskBase
from mobigrasp.host.task_sense import odom_to_platform_q4, platform_to_odom_mm, spoke_reading

ROLL_SCAN_MRAD = 524  # 30 degrees
ROLL_SCAN_STEPS = 2  # 0, -30, -60 degrees from the pi/2 roll cover the quarter turn
# grasp check after the lift: the object's marker seen this close to where it stood, in this many
# frames of the look, is the object still standing there (the fingers closed beside it); the
# world's grasp tolerance is 15 mm, a miss is 20+ mm off, the marker estimate a few mm at 0.2 m
CHECK_AWAY_MM = 60  # seen farther than this from the fingertip: standing, not held
CHECK_SEEN_FRAMES = 2
CHECK_POSE_US = 500_000  # look this long (7 frames at 15 fps) at each waist offset, settled
# the waist turns the view about the place: the estimate that put the fingers beside the object
# may be off by 0.3 rad in bearing (random 001 seed 5017: 56 mm at 0.16 m, blind on odometry)
CHECK_WAIST_MRAD = (0, 300, -300)
MAX_REGRASPS = 2
# views of the check, (range to the place mm, pitch down mrad), first reachable wins: from
# 0.3 m the 320 x 240 frame spans 157 x 118 mm there (f = 611 px), room for the miss itself
# (the estimate that guided the fingers beside the object is off by that much); the dual "+"
# (47.3 mm apart) stays resolved; the short 000 arm reaches the nearer views only
CHECK_VIEWS = ((300, 1047), (250, 1047), (300, 785), (250, 785), (200, 1047), (200, 785),
               (160, 1047), (250, 1309), (200, 524), (150, 524), (150, 785))
CHECK_DETECTORS = {"000": ("dual_plus", "radial_symbol"), "001": ("dual_plus", "radial_symbol"),
                   "002": ("red_cylinder",)}


class GraspStates(TaskBase):
    """Entry actions and handlers of the grasp states."""

    def _object_target_q4(self, inp, height_mm: int, back_mm: int = 0) -> tuple[int, int, int]:
        x, y = self.obj_platform(inp)
        if back_mm:
            rho = isqrt(x * x + y * y)
            if rho > back_mm * 16:
                x, y = x * (rho - back_mm * 16) // rho, y * (rho - back_mm * 16) // rho
        return x, y, (height_mm - self.p.h_shoulder_mm) * 16

    # --- ROUGH_GRASP --------------------------------------------------------------------------
    def enter_ROUGH_GRASP(self, now: int, inp) -> None:
        self.wheels = (0, 0)
        self.gripper = 0
        if self.method == "002":
            target = self._object_target_q4(inp, self.p.grasp_height_mm, self.p.pregrasp_back_mm)
        else:
            target = self._object_target_q4(inp, self.p.object_top_mm + self.p.hover_mm)
            self.grasp_xy_q4 = target[:2]
            if self.plus_odom is not None:  # hover over the nearer "+", grasp on the axis
                pts = [odom_to_platform_q4(inp.x_mm, inp.y_mm, inp.heading_mrad,
                                           self.p.mount_forward_mm, *q) for q in self.plus_odom]
                near = min(pts, key=lambda q: q[0] * q[0] + q[1] * q[1])
                target = (near[0], near[1], target[2])
        pose = self.grasp_ik(target)
        if isinstance(pose, kinematics.Unreachable) and self.method != "002":
            # a few mm beyond reach (the base stopped a little far): hover lower, in 10 mm
            # steps down to half the hover height; the precise grasp descends anyway
            for drop_mm in range(10, self.p.hover_mm // 2 + 1, 10):
                lower = (target[0], target[1], target[2] - drop_mm * 16)
                pose = self.grasp_ik(lower)
                if not isinstance(pose, kinematics.Unreachable):
                    target = lower
                    break
        self.note(rough_target_mm=[v // 16 for v in target])
        if isinstance(pose, kinematics.Unreachable):
            self.fail(now, f"rough grasp IK: {pose.reason}")
            return
        self.grasp_alpha = pose.alpha_mrad
        self.apply_pose(now, pose, 0)
        self.note(rough_pose_mrad=[pose.theta2_mrad, pose.theta3_mrad, pose.theta4_mrad,
                                   pose.theta5_mrad])

    def do_ROUGH_GRASP(self, now: int, inp, dets: dict) -> None:
        self.wheels = (0, 0)
        if self.settled(now):
            self.go(now, "PRECISE_GRASP", "arm at the rough grasp pose")

    # --- PRECISE_GRASP ------------------------------------------------------------------------
    def enter_PRECISE_GRASP(self, now: int, inp) -> None:
        self.precise_steps = 0
        self.phase_us = now
        if self.method == "002":
            # the pitch is chosen again (level first, eq. (4) of 002): the pre-grasp point
            # may only be reachable tilted, the axis often level
            target = self._object_target_q4(inp, self.p.grasp_height_mm)
            pose = self.grasp_ik(target)
            if isinstance(pose, kinematics.Unreachable):
                self.fail(now, f"precise grasp IK: {pose.reason}")
                return
            self.apply_pose(now, pose)
            self.phase = "lower"
            return
        self.set_arm(now, *self.arm[2:6], th1=kinematics.ROLL_PRECISE_MRAD)
        self.phase = "roll"
        self.roll_scan = 0

    def _move_point(self, now: int, x: int, y: int, z: int, th1: int | None = None) -> bool:
        pose = self.grasp_ik((x, y, z), self.grasp_alpha)
        if isinstance(pose, kinematics.Unreachable):
            self.note(precise_unreachable=pose.reason)
            return False
        self.apply_pose(now, pose, th1)
        return True

    def _descend(self, now: int, why: str) -> None:
        x, y, _ = self.gripper_point_q4()
        if self.grasp_xy_q4 is not None and self.p.precise_align_ch == 1:
            x, y = self.grasp_xy_q4  # from above the "+" to the object's axis
        z = (self.p.grasp_height_mm - self.p.h_shoulder_mm) * 16
        if not self._move_point(now, x, y, z):
            self.fail(now, "precise grasp: grasp height unreachable")
            return
        self.phase = "lower"
        self.note(precise_descend=why)

    def do_PRECISE_GRASP(self, now: int, inp, dets: dict) -> None:
        self.wheels = (0, 0)
        if self.phase == "roll":
            if self.settled(now):
                self.phase, self.phase_us = "align", now
            return
        if self.phase == "align":
            self._align(now, dets.get("spoke"))
            return
        if self.phase == "lower":
            if self.settled(now):
                self.gripper = 1000
                self.phase, self.phase_us = "close", now
            return
        if self.phase == "close":
            if inp.grasp_closed:
                self.go(now, "LIFT", "gripper closed on the object")
            elif now - self.phase_us >= self.p.grasp_close_timeout_us:
                self.fail(now, "gripper closed but no object held")

    def _align(self, now: int, det) -> None:
        if not self.settled(now):
            return  # the frame may predate the last move
        try:
            reading = spoke_reading(det)
        except (ValueError, TypeError):
            self.counters["bad_detections"] += 1
            reading = None
        if reading is None:
            waited = now - self.phase_us
            if self.roll_scan < ROLL_SCAN_STEPS and waited >= self.p.spoke_wait_us // 3:
                # the spoke detector sees arms within 30 degrees of the image x axis: roll the
                # camera by 30 degrees at a time over the quarter turn the "+" repeats in
                self.roll_scan += 1
                x, y, z = self.gripper_point_q4()
                self._move_point(now, x, y, z, self.arm[1] - ROLL_SCAN_MRAD)
                self.phase_us = now
            elif waited >= self.p.spoke_wait_us:
                self._descend(now, f"no spoke seen for {waited} us: rough position")
            return
        self.phase_us = now
        self.precise_steps += 1
        step = kinematics.precise_grasp_step(self.arm[5], reading[0], reading[1])
        self.note(precise={"spoke_mrad": reading[0], "w_px": reading[1], "reason": step.reason,
                           "step": self.precise_steps})
        if step.aligned:
            self._descend(now, f"k_T ~ 0 and w_T = {reading[1]} px")
            return
        if self.precise_steps >= self.p.precise_max_steps:
            self._descend(now, f"not aligned after {self.precise_steps} steps: {step.reason}")
            return
        x, y, z = self.gripper_point_q4()
        if self.p.precise_align_ch == 1:
            # roll about the vertical l3: the gripper stays above the object; the spokes repeat
            # every quarter turn, so stay inside the roll limits by taking the neighbour spoke
            roll = self.arm[1] + step.d_align_mrad
            lo, hi = arm_calib.JOINT_LIMITS_MRAD[1]
            roll += -kinematics.QUARTER_TURN_MRAD if roll > hi else (
                kinematics.QUARTER_TURN_MRAD if roll < lo else 0)
            self._move_point(now, x, y, z + step.dz_mm * 16, roll)
            return
        rho = isqrt(x * x + y * y)
        nx = (rho * sin_q12(step.theta5_mrad) + 2048) >> 12
        ny = (rho * cos_q12(step.theta5_mrad) + 2048) >> 12
        self._move_point(now, nx, ny, z + step.dz_mm * 16, step.theta1_mrad)

    # --- LIFT ---------------------------------------------------------------------------------
    def enter_LIFT(self, now: int, inp) -> None:
        self.phase, self.check_seen = "raise", 0
        x, y, z = self.gripper_point_q4()
        if not self._move_point(now, x, y, z + self.p.lift_mm * 16):
            # out of reach straight up: raise the shoulder instead
            self.set_arm(now, self.arm[2], self.arm[3], self.arm[4] + 300, self.arm[5])

    def do_LIFT(self, now: int, inp, dets: dict) -> None:
        self.wheels = (0, 0)
        if not inp.grasp_closed:
            self.fail(now, "object dropped during the lift")
            return
        if self._seen_standing(now, inp, dets):
            return
        if self.phase == "raise":
            if self.settled(now):
                self._start_check(now, inp)
            return
        self._check(now)

    def _check_pose(self, inp):
        """A camera pose looking down at the grasp place from ``CHECK_VIEWS`` (range, pitch):
        back along the place's bearing and up, by eq. (11) of 000 with alpha_T = -pitch; the
        first the arm reaches.  The gripper, and a held object, are then behind and below the
        camera's view; None if no view is reachable."""
        if self.obj is None:
            return None
        x, y = self.obj_platform(inp)
        rho = isqrt(x * x + y * y)
        look_mm = self.p.object_top_mm // 2 if self.method == "002" else self.p.object_top_mm
        for d_mm, pitch in CHECK_VIEWS:
            back = d_mm * 16 * cos_q12(pitch) >> 12
            r = rho - back
            if r < 20 * 16:
                continue
            z = (look_mm - self.p.h_shoulder_mm) * 16 + (d_mm * 16 * sin_q12(pitch) >> 12)
            pose = kinematics.ik_pitch_mm_q4(self.geom, (x * r // rho, y * r // rho, z), -pitch)
            if isinstance(pose, kinematics.ArmPose):
                return pose
        return None

    def _start_check(self, now: int, inp) -> None:
        """Swing the camera to look back at the grasp place (``_check_pose``; out of the
        views' reach, the search's far look toward it); the waist then turns through
        ``CHECK_WAIST_MRAD``."""
        pose = self._check_pose(inp)
        if pose is not None:
            self.apply_pose(now, pose)
            self.note(grasp_check_pose_mrad=[pose.theta2_mrad, pose.theta3_mrad,
                                             pose.theta4_mrad, pose.theta5_mrad])
        elif self.obj is not None:
            # seen (or estimated) beyond the views' reach: the search's far look toward it
            sp = SearchParams(**self.p.search)
            x, y = self.obj_platform(inp)
            self.set_arm(now, sp.coarse_theta2_mrad[0], sp.theta3_mrad, sp.theta4_mrad,
                         atan2_mrad(x, y))
            self.note(grasp_check_far_look=True)
        self.trust_from_us = self.move_done_us  # frames of the swing: arm pose unknown
        self.check_waist = (self.arm[5], 0)  # (centre, index into CHECK_WAIST_MRAD)
        self.phase, self.phase_us = "check", self.move_done_us

    def _standing_away(self, inp) -> bool:
        """The object just seen (self.obj) stands on the ground away from the gripper, not
        under the fingertip where a held object would be (there is one object: seen anywhere
        else, it is not in the gripper; random 002 seed 1004 closed 0.45 m short of it)."""
        tip = platform_to_odom_mm(inp.x_mm, inp.y_mm, inp.heading_mrad,
                                  self.p.mount_forward_mm, self.gripper_point_q4())
        dx, dy = self.obj[0] - tip[0], self.obj[1] - tip[1]
        return dx * dx + dy * dy > CHECK_AWAY_MM * CHECK_AWAY_MM

    def _seen_standing(self, now: int, inp, dets: dict) -> bool:
        """Count this frame's sightings of the object standing away from the gripper (also
        while the arm still rises: the frame may show it already); True once that makes a
        miss, handled here: open and ADJUST again, or FAILED after ``MAX_REGRASPS``."""
        place = self.obj
        for name in CHECK_DETECTORS[self.method]:
            det = dets.get(name)
            if det is None or place is None or not self.see_object(now, inp, name, det):
                continue
            if self._standing_away(inp):
                self.check_seen += 1
                self.note(grasp_check_seen={"name": name, "obj_mm": list(self.obj),
                                            "estimate_mm": list(place)})
                break
            self.obj = place  # the held object under the fingertip: keep the estimate
        if self.check_seen < CHECK_SEEN_FRAMES:
            return False
        self.regrasps = getattr(self, "regrasps", 0) + 1
        if self.regrasps > MAX_REGRASPS:
            self.fail(now, f"grasp check: object still standing after {self.regrasps} grasps")
            return True
        self.gripper = 0
        self.go(now, "ADJUST", f"grasp check: object still standing away from the gripper "
                f"(seen in {self.check_seen} frames): open and grasp again")
        return True

    def _check(self, now: int) -> None:
        """The look of the grasp check: each waist offset for ``CHECK_POSE_US``, then DONE."""
        if not self.settled(now) or now - self.phase_us < CHECK_POSE_US:
            return
        centre, k = self.check_waist
        if k + 1 < len(CHECK_WAIST_MRAD):  # the next waist offset: the estimate may be off
            self.check_waist = (centre, k + 1)
            self.set_arm(now, *self.arm[2:5], centre + CHECK_WAIST_MRAD[k + 1])
            self.trust_from_us = self.move_done_us
            self.phase_us = self.move_done_us
            return
        self.go(now, "DONE", f"object lifted by {self.p.lift_mm} mm and not seen standing "
                f"(grasp check)")
