"""Grasp states of the task: ROUGH_GRASP, PRECISE_GRASP and LIFT (000 §III.C, 002 §4).

Targets in the platform frame, Q4 mm; each handler takes the task ``t`` first; where the
methods differ (the rough target, the precise grasp's start) it asks ``t.rules``:

- ROUGH_GRASP (000 §III.C.1): the gripper above the object top by ``hover_mm``, pitched
  alpha_T = -pi/2, by eq. (11) of 000 (host.kinematics).  001 (``Method.sight_views``) first
  looks back at the top with the base standing still and grasps on that sighting (ours,
  docs/task.md): its ADJUST ends on odometry. Arrived on its grasp circle, 001 decides after
  the look (``Method.look_decides``): the grasp by eq. (11) straight from there when the look
  confirms the object, else ADJUST.  002: the pre-grasp point
  ``pregrasp_back_mm`` short of the cylinder axis at the grasp height, horizontal gripper by
  eq. (4) of 002 (tilting down to -0.28 rad if the level pose is outside the joint limits);
  first the base drives the object into the reach where the grasp itself is level
  (``Method.grasp_reach_mm``).
- PRECISE_GRASP (000 §III.C.2): roll theta1 to pi/2, then on each spoke reading turn
  until k_T = 0 and move up/down until w_T is in [20, 40] px; then down to the grasp height and
  close.  The turn is made with the wrist roll by default (``precise_align_ch`` = 1): with the
  gripper vertical it turns the image like the waist does, but does not swing the gripper
  sideways by r * d_theta5 (20 mm at r = 140 mm for 0.15 rad, more than the grasp tolerance);
  ``precise_align_ch`` = 5 turns the waist as the brief reads 000.  No spoke for
  ``spoke_wait_us``: the method may search for the object instead (``Method.grasp_lost``);
  else, or after too many steps, go down on the rough position (the trace's ``grasp_close``).
  002: move in from the pre-grasp point to the axis and close; the pitch is chosen again there
  (level first), since with theta2 <= 0 the pre-grasp point may be reachable only tilted.
- LIFT: raise by ``lift_mm`` with the same pitch, then the grasp check (ours: the papers end at
  the closed gripper, and the host has no finger sensor, FLAG_GRIPPER_CLOSED only says the close
  was commanded), on positive evidence only (docs/task.md): the camera, at the fingertip point
  of eq. (3) of 000, goes straight up above where it is and looks down (``HELD_VIEW_MM``; 002
  its own look, ``Method.held_view_pose``); the waist then turns through ``CHECK_WAIST_MRAD``.
  The camera inside a held object sees it fill the frame (``Method.held_in_view``): that at two
  waist offsets whose fingertip places are ``HELD_MOVE_MM`` apart, the object has moved with
  the gripper: DONE.  Seen standing away from the fingertip (``CHECK_AWAY_MM``, in
  ``CHECK_SEEN_FRAMES`` frames), or no such frames by the end of the look, is a miss: open,
  ADJUST and grasp again (up to ``MAX_REGRASPS`` times), then FAILED; after a blind grasp
  (``CLOSES_ON_SIGHT``) with no evidence the grasp again goes only on a sighting made since
  (else LOST: the search).  Not seeing the object is never evidence of holding it.  No grasp
  is tried unless the object itself (not a guide board) has been seen
  (``Method.object_detectors``): FAILED "no graspable object found".
"""

from __future__ import annotations

from mobigrasp.host import arm_calib, kinematics
from mobigrasp.host.fixedpoint import atan2_mrad, cos_q12, isqrt, sin_q12
from mobigrasp.host.task.drive import close_in
from mobigrasp.host.task.sense import (
    platform_to_odom_mm,
    spoke_reading,
)
from mobigrasp.host.task.sonar_guard import close_echo

ROLL_SCAN_MRAD = 524  # 30 degrees
ROLL_SCAN_STEPS = 2  # 0, -30, -60 degrees from the pi/2 roll cover the quarter turn
# grasp check after the lift: the object's marker seen this close to where it stood, in this many
# frames of the look, is the object still standing there (the fingers closed beside it); the
# world's grasp tolerance is 15 mm, a miss is 20+ mm off, the marker estimate a few mm at 0.2 m
CHECK_AWAY_MM = 60  # seen farther than this from the fingertip: standing, not held
CHECK_SEEN_FRAMES = 2
CHECK_POSE_US = 500_000  # look this long (7 frames at 15 fps) at each waist offset, settled
# the waist turns the view about the place: the estimate that put the fingers beside the object
# may be off by 0.3 rad in bearing (docs/cosim.md "Measured", T8)
CHECK_WAIST_MRAD = (0, 300, -300)
MAX_REGRASPS = 2
# the look of the check (docs/task.md): the camera this far above the object's top, looking
# down, first reachable wins (an object left standing where the fingers closed is then in view);
# the held object fills the frame at two waist offsets whose fingertip places are HELD_MOVE_MM
# apart (r * 0.3 rad >= 33 mm at the reach r >= 110 mm of a 000 grasp): a standing object, whose
# radius is 20-25 mm, cannot hold the camera at both
HELD_VIEW_MM = (150, 140, 130, 120, 110, 100, 90)
HELD_MOVE_MM = 25

# the look before the rough grasp (Method.sight_views): this many dual "+" sightings, each look
# (waist offset, wrist roll) held this long (10 frames at 15 fps) until the pair is seen. The
# pitched view spans ~90 mm across but only ~55 mm along the line of sight, where a pair along
# it is cut by the frame's edge when the estimate is 15 mm off: a quarter roll lays the line of
# sight along the frame's width; the waist offsets move the view ~18 mm aside (docs/task.md).
# Seen outside ADJUST's goal window, the base closes in again, at most this often a grasp
SIGHT_FRAMES = 3
SIGHT_LOOK_US = 700_000
SIGHT_LOOKS_MRAD = ((0, 0), (0, 1571), (150, 1571), (150, 0), (-150, 0), (-150, 1571))
MAX_SIGHT_ADJUSTS = 2
# closes decided on the camera's view of the object where the fingers went (descend): the
# spoke aligned or seen until the steps ran out, 001's look confirming it; the others are blind
CLOSES_ON_SIGHT = ("precise", "max_steps", "ik")
# the retry after a blind miss with no evidence, the object not seen since (docs/task.md)
REGRASP_UNSEEN = "grasp missed at the estimate, object not seen since: searching before " \
    "grasping again"



class GraspStates:
    """Entry actions and steps of the grasp states."""

    def object_target_q4(self, t, inp, height_mm: int, back_mm: int = 0
                         ) -> tuple[int, int, int]:
        """The object's axis at ``height_mm`` above the ground, ``back_mm`` short of it along
        the line from the waist (platform frame, Q4 mm)."""
        x, y = t.obj_platform(inp)
        if back_mm:
            rho = isqrt(x * x + y * y)
            if rho > back_mm * 16:
                x, y = x * (rho - back_mm * 16) // rho, y * (rho - back_mm * 16) // rho
        return x, y, (height_mm - t.p.h_shoulder_mm) * 16

    def enter_ROUGH_GRASP(self, t, now: int, inp) -> None:
        t.wheels = (0, 0)
        t.gripper = 0
        if not t.graspable_seen and t.rules.object_cue_seen(t):
            # ADJUST finished on an estimate the object's detector never confirmed, though a
            # cue of the object was seen (docs/task.md): search again, the estimate dropped (it
            # was looked at and the object is not there; kept, it decided the next approach)
            t.obj = None
            t.lost_in = "ROUGH_GRASP"
            t.go(now, "LOST", "object never sighted at its estimated place, its cue seen "
                 "before: searching before any grasp")
            return
        if not t.graspable_seen:
            # the estimate came from a guide (002's board) alone: nothing seen to grasp
            t.fail(now, f"no graspable object found ({', '.join(t.rules.object_detectors)} "
                        f"never seen)")
            return
        if t.regrasps and not t.object_sighted and not t.rules.sight_views:
            # a grasp at this estimate found no evidence and the camera has not seen the
            # object since (docs/task.md): the same blind grasp again would miss again
            t.lost_in = "ROUGH_GRASP"
            t.go(now, "LOST", REGRASP_UNSEEN)
            return
        t.reach_mm = t.rules.grasp_reach_mm(t)
        if t.reach_mm is not None:
            x, y = t.obj_platform(inp)
            dist = isqrt(x * x + y * y) // 16
            if abs(dist - t.reach_mm[0]) > t.reach_mm[1]:
                # the grasp pose needs the object elsewhere (002's level grasp): drive there
                t.note(grasp_reach={"dist_mm": dist, "goal_mm": t.reach_mm[0],
                                    "tol_mm": t.reach_mm[1]})
                t.phase = "reach"
                return
        pose = self._view_pose(t, inp, t.rules.sight_views) if t.rules.sight_views else None
        if pose is None:
            self._rough_pose(t, now, inp)
            return
        # the look before the grasp (Method.sight_views): the base stands still from here on
        t.apply_pose(now, pose, SIGHT_LOOKS_MRAD[0][1])
        t.trust_from_us = t.move_done_us  # frames of the swing: arm pose unknown
        t.sight_frames, t.sight_look, t.sight_th5 = 0, 0, pose.theta5_mrad
        t.phase, t.phase_us = "sight", t.move_done_us
        t.note(sight_pose_mrad=[pose.theta2_mrad, pose.theta3_mrad, pose.theta4_mrad,
                                pose.theta5_mrad])

    def _sight(self, t, now: int, inp, dets: dict) -> None:
        """The look before the grasp: sightings of the dual "+" with the base standing still
        give the estimate the grasp goes on (and the "+" it hovers over). Each look of
        ``SIGHT_LOOKS_MRAD`` is held for ``SIGHT_LOOK_US`` until the pair is seen
        (``SIGHT_FRAMES`` frames, or fewer by the end of that look). Seen outside ADJUST's
        goal window, the base closes in again first (up to ``MAX_SIGHT_ADJUSTS`` times a
        grasp). Not seen at any look: an object the camera never saw (001's P_i carried on
        odometry), or has not seen since a grasp on this estimate found no evidence, is
        searched for (LOST); else the grasp goes on the estimate as it was."""
        det = dets.get("dual_plus")
        if det is not None and t.settled(now) and t.see_object(now, inp, "dual_plus", det):
            t.sight_frames += 1
        if t.sight_frames < SIGHT_FRAMES and now - t.phase_us < SIGHT_LOOK_US:
            return
        k = t.sight_look
        if not t.sight_frames and k + 1 < len(SIGHT_LOOKS_MRAD):
            t.sight_look = k + 1  # not seen: the next look
            d_th5, roll = SIGHT_LOOKS_MRAD[k + 1]
            t.set_arm(now, *t.arm[2:5], t.sight_th5 + d_th5, roll)
            t.trust_from_us = t.move_done_us
            t.phase_us = t.move_done_us
            return
        x, y = t.obj_platform(inp)
        dist = isqrt(x * x + y * y) // 16
        goal_mm, tol_mm = t.rules.adjust_goal_mm(t)
        t.note(sight={"frames": t.sight_frames, "look_mrad": list(SIGHT_LOOKS_MRAD[k]),
                      "dist_mm": dist, "bearing_mrad": atan2_mrad(x, y)})
        if t.rules.look_decides(t, now, inp):
            return  # the method's grasp on this look (001 from its grasp circle)
        if not t.sight_frames and not t.object_sighted:
            t.lost_in = "ROUGH_GRASP"
            t.go(now, "LOST", REGRASP_UNSEEN if t.regrasps else "object not seen at its "
                 "estimated place, never seen by the camera: searching before any grasp")
            return
        if t.sight_frames and abs(dist - goal_mm) > tol_mm \
                and t.sight_adjusts < MAX_SIGHT_ADJUSTS:
            t.sight_adjusts += 1
            t.go(now, "ADJUST", f"object sighted {dist} mm ahead of the waist, outside "
                 f"{goal_mm} +- {tol_mm} mm: closer in first")
            return
        self._rough_pose(t, now, inp)

    def _rough_pose(self, t, now: int, inp) -> None:
        """The gripper above the object by ``hover_mm`` (``Method.rough_target``)."""
        t.phase = ""
        target = t.rules.rough_target(t, inp)
        pose = t.grasp_ik(target)
        if isinstance(pose, kinematics.Unreachable) and t.rules.lowers_hover():
            # a few mm beyond reach (the base stopped a little far): hover lower, in 10 mm
            # steps down to half the hover height; the precise grasp descends anyway
            for drop_mm in range(10, t.p.hover_mm // 2 + 1, 10):
                lower = (target[0], target[1], target[2] - drop_mm * 16)
                pose = t.grasp_ik(lower)
                if not isinstance(pose, kinematics.Unreachable):
                    target = lower
                    break
        t.note(rough_target_mm=[v // 16 for v in target])
        if isinstance(pose, kinematics.Unreachable) and t.sight_adjusts < MAX_SIGHT_ADJUSTS:
            # the object beside or behind the arm's reach (001 arrived on its grasp circle
            # facing past it, docs/task.md): the base closes in on it first, as after a look
            # that saw it outside ADJUST's goal
            t.sight_adjusts += 1
            t.go(now, "ADJUST", f"rough grasp out of reach ({pose.reason}): closer in first")
            return
        if isinstance(pose, kinematics.Unreachable):
            t.fail(now, f"rough grasp IK: {pose.reason}")
            return
        t.grasp_alpha = pose.alpha_mrad
        t.apply_pose(now, pose, 0)
        t.note(rough_pose_mrad=[pose.theta2_mrad, pose.theta3_mrad, pose.theta4_mrad,
                                   pose.theta5_mrad])

    def do_ROUGH_GRASP(self, t, now: int, inp, dets: dict) -> None:
        t.wheels = (0, 0)
        if t.phase == "reach":
            goal_mm, tol_mm = t.reach_mm
            wheels, done, _ = close_in(t.obj_platform(inp), goal_mm, tol_mm,
                                       t.p.bearing_tol_mrad, t.rules.adjust_vmax_mmps(t.p))
            echo = close_echo(t, inp) if wheels[0] + wheels[1] > 0 else None
            if echo is not None:  # something in front of the object: grasp from here
                t.note(close_guard=echo)
            if done or echo is not None:
                self._rough_pose(t, now, inp)
            else:
                t.wheels = wheels
        elif t.phase == "sight":
            self._sight(t, now, inp, dets)
        elif t.settled(now):
            t.go(now, "PRECISE_GRASP", "arm at the rough grasp pose")

    def enter_PRECISE_GRASP(self, t, now: int, inp) -> None:
        t.sight_adjusts = 0  # the next grasp's look may send the base closer again
        t.precise_steps = 0
        t.close_by = None
        t.phase_us = now
        t.rules.enter_precise(t, now, inp)

    def move_point(self, t, now: int, x: int, y: int, z: int, th1: int | None = None) -> bool:
        pose = t.grasp_ik((x, y, z), t.grasp_alpha)
        if isinstance(pose, kinematics.Unreachable):
            t.note(precise_unreachable=pose.reason)
            return False
        t.apply_pose(now, pose, th1)
        return True

    def descend(self, t, now: int, why: str, condition: str) -> None:
        """Down to the grasp height, then close; ``condition`` says what decided it (the
        trace's ``grasp_close``): "precise" (k_T = 0 and w_T in [w_min, w_max], 000
        §III.C.2), "ik" (001's grasp by eq. (11) from its grasp circle, method001.py), or a
        fallback, "no_spoke" or "max_steps"."""
        x, y, _ = t.gripper_point_q4()
        if t.grasp_xy_q4 is not None and t.p.precise_align_ch == 1:
            x, y = t.grasp_xy_q4  # from above the "+" to the object's axis
        z = (t.p.grasp_height_mm - t.p.h_shoulder_mm) * 16
        if not self.move_point(t, now, x, y, z):
            t.fail(now, "precise grasp: grasp height unreachable")
            return
        t.phase = "lower"
        t.close_by = condition
        t.note(precise_descend=why)

    def do_PRECISE_GRASP(self, t, now: int, inp, dets: dict) -> None:
        t.wheels = (0, 0)
        if t.phase == "roll":
            if t.settled(now):
                t.phase, t.phase_us = "align", now
            return
        if t.phase == "align":
            self._align(t, now, dets.get("spoke"))
            return
        if t.phase == "lower":
            if t.settled(now):
                t.gripper = 1000
                t.phase, t.phase_us = "close", now
                # what closed the gripper; "pose_reached": the move-in of 002, no alignment
                t.note(grasp_close=t.close_by or "pose_reached")
            return
        if t.phase == "close":
            if inp.grasp_closed:
                t.go(now, "LIFT", "gripper closed on the object")
            elif now - t.phase_us >= t.p.grasp_close_timeout_us:
                t.fail(now, "gripper closed but no object held")

    def _align(self, t, now: int, det) -> None:
        if not t.settled(now):
            return  # the frame may predate the last move
        try:
            reading = spoke_reading(det)
        except (ValueError, TypeError):
            t.counters["bad_detections"] += 1
            reading = None
        if reading is None:
            waited = now - t.phase_us
            if t.roll_scan < ROLL_SCAN_STEPS and waited >= t.p.spoke_wait_us // 3:
                # the spoke detector sees arms within 30 degrees of the image x axis: roll the
                # camera by 30 degrees at a time over the quarter turn the "+" repeats in
                t.roll_scan += 1
                x, y, z = t.gripper_point_q4()
                self.move_point(t, now, x, y, z, t.arm[1] - ROLL_SCAN_MRAD)
                t.phase_us = now
            elif waited >= t.p.spoke_wait_us and not t.rules.grasp_lost(t, now, waited):
                self.descend(t, now, f"no spoke seen for {waited} us: rough position",
                              "no_spoke")
            return
        t.phase_us = now
        t.precise_steps += 1
        step = kinematics.precise_grasp_step(t.arm[5], reading[0], reading[1],
                                             w_min_px=t.p.w_min_px, w_max_px=t.p.w_max_px)
        t.note(precise={"spoke_mrad": reading[0], "w_px": reading[1], "reason": step.reason,
                           "step": t.precise_steps})
        if step.aligned:
            self.descend(t, now, f"k_T ~ 0 and w_T = {reading[1]} px", "precise")
            return
        if t.precise_steps >= t.p.precise_max_steps:
            self.descend(t, now, f"not aligned after {t.precise_steps} steps: {step.reason}",
                          "max_steps")
            return
        x, y, z = t.gripper_point_q4()
        if t.p.precise_align_ch == 1:
            # roll about the vertical l3: the gripper stays above the object; the spokes repeat
            # every quarter turn, so stay inside the roll limits by taking the neighbour spoke
            roll = t.arm[1] + step.d_align_mrad
            lo, hi = arm_calib.JOINT_LIMITS_MRAD[1]
            roll += -kinematics.QUARTER_TURN_MRAD if roll > hi else (
                kinematics.QUARTER_TURN_MRAD if roll < lo else 0)
            self.move_point(t, now, x, y, z + step.dz_mm * 16, roll)
            return
        rho = isqrt(x * x + y * y)
        nx = (rho * sin_q12(step.theta5_mrad) + 2048) >> 12
        ny = (rho * cos_q12(step.theta5_mrad) + 2048) >> 12
        self.move_point(t, now, nx, ny, z + step.dz_mm * 16, step.theta1_mrad)

    def enter_LIFT(self, t, now: int, inp) -> None:
        t.phase, t.check_seen = "raise", 0
        x, y, z = t.gripper_point_q4()
        if not self.move_point(t, now, x, y, z + t.p.lift_mm * 16):
            # out of reach straight up: raise the shoulder instead
            t.set_arm(now, t.arm[2], t.arm[3], t.arm[4] + 300, t.arm[5])

    def do_LIFT(self, t, now: int, inp, dets: dict) -> None:
        t.wheels = (0, 0)
        if not inp.grasp_closed:
            t.fail(now, "object dropped during the lift")
            return
        if self._seen_standing(t, now, inp, dets):
            return
        if t.phase == "raise":
            if t.settled(now):
                self.start_check(t, now, inp)
            return
        self._check(t, now, inp)

    def _view_pose(self, t, inp, views):
        """A camera pose looking down at the object's top from ``views`` (range mm, pitch
        down mrad): back along the place's bearing and up, by eq. (11) of 000 with alpha_T =
        -pitch; the first the arm reaches. None if no view is reachable."""
        if t.obj is None:
            return None
        x, y = t.obj_platform(inp)
        rho = isqrt(x * x + y * y)
        look_mm = t.rules.look_height_mm(t.p, True)
        for d_mm, pitch in views:
            back = d_mm * 16 * cos_q12(pitch) >> 12
            r = rho - back
            if r < 20 * 16:
                continue
            z = (look_mm - t.p.h_shoulder_mm) * 16 + (d_mm * 16 * sin_q12(pitch) >> 12)
            pose = kinematics.ik_pitch_mm_q4(t.geom, (x * r // rho, y * r // rho, z), -pitch)
            if isinstance(pose, kinematics.ArmPose):
                return pose
        return None

    def _held_pose(self, t):
        """The look of the grasp check: the camera (the fingertip point, eq. (3) of 000)
        straight above where it is, looking down, ``HELD_VIEW_MM`` above the object's top,
        the first height the arm reaches (an object left standing is then in view below it).
        None if no height is reachable."""
        x, y, _ = t.gripper_point_q4()
        for h_mm in HELD_VIEW_MM:
            z = (t.p.object_top_mm + h_mm - t.p.h_shoulder_mm) * 16
            pose = kinematics.ik_pitch_mm_q4(t.geom, (x, y, z), kinematics.ALPHA_DOWN_MRAD)
            if isinstance(pose, kinematics.ArmPose):
                return pose
        return None

    def start_check(self, t, now: int, inp) -> None:
        """Raise the camera above the gripper looking down (``_held_pose``); the waist then
        turns through ``CHECK_WAIST_MRAD`` (the gripper, and a held object, move with it)."""
        t.held_tips = {}
        pose = t.rules.held_view_pose(t) or self._held_pose(t)
        if pose is not None:
            t.apply_pose(now, pose)
            t.note(grasp_check_pose_mrad=[pose.theta2_mrad, pose.theta3_mrad,
                                             pose.theta4_mrad, pose.theta5_mrad])
        else:
            t.note(grasp_check_no_view=True)  # no evidence can come: a miss at the end
        t.trust_from_us = t.move_done_us  # frames of the swing: arm pose unknown
        t.check_waist = (t.arm[5], 0)  # (centre, index into CHECK_WAIST_MRAD)
        t.held_tips = {}
        t.phase, t.phase_us = "check", t.move_done_us

    def _tip_odom(self, t, inp) -> tuple[int, int]:
        tip = platform_to_odom_mm(inp.x_mm, inp.y_mm, inp.heading_mrad,
                                  t.p.mount_forward_mm, t.gripper_point_q4())
        return tip[0], tip[1]

    def _seen_standing(self, t, now: int, inp, dets: dict) -> bool:
        """This frame during the look: the held object filling it (``Method.held_in_view``,
        kept per waist offset as grasp evidence), or the object seen standing away from the
        gripper (``CHECK_AWAY_MM``; also while the arm still rises). True once the sightings
        away make a miss, handled here (:meth:`missed`)."""
        place = t.obj
        if t.phase == "check" and t.settled(now) and t.rules.held_in_view(t, now, dets):
            t.held_tips[t.check_waist[1]] = self._tip_odom(t, inp)
        for name in t.rules.check_detectors:
            det = dets.get(name)
            if det is None or place is None or not t.see_object(now, inp, name, det):
                continue
            tip = self._tip_odom(t, inp)
            d2 = (t.obj[0] - tip[0]) ** 2 + (t.obj[1] - tip[1]) ** 2
            if d2 > CHECK_AWAY_MM * CHECK_AWAY_MM:
                t.check_seen += 1
                t.note(grasp_check_seen={"name": name, "obj_mm": list(t.obj),
                                            "estimate_mm": list(place)})
                break
            t.obj = place  # seen near the fingertip's place: keep the estimate
        if t.check_seen < CHECK_SEEN_FRAMES:
            return False
        self.missed(t, now, f"object still standing away from the gripper (seen in "
                    f"{t.check_seen} frames)")
        return True

    def missed(self, t, now: int, why: str) -> None:
        """No grasp: open and ADJUST again, up to ``MAX_REGRASPS`` times, then FAILED."""
        t.regrasps += 1
        if t.regrasps > MAX_REGRASPS:
            t.fail(now, f"grasp check: {why}, after {t.regrasps} grasps")
            return
        t.gripper = 0
        t.go(now, "ADJUST", f"grasp check: {why}: open and grasp again")

    @staticmethod
    def held_evidence(held_tips: dict) -> bool:
        """The held object filled the frame at two waist offsets whose fingertip places are at
        least ``HELD_MOVE_MM`` apart: it moved with the gripper (a standing object cannot hold
        the camera at both)."""
        tips = list(held_tips.values())
        return any((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 >= HELD_MOVE_MM * HELD_MOVE_MM
                   for i, a in enumerate(tips) for b in tips[i + 1:])

    def _check(self, t, now: int, inp=None) -> None:
        """The look of the grasp check: each waist offset for ``CHECK_POSE_US``; DONE on
        positive evidence (:meth:`held_evidence`), else a miss."""
        if self.held_evidence(t.held_tips):
            t.go(now, "DONE", f"object held: it fills the hand camera's frame at waist offsets "
                 f"{sorted(CHECK_WAIST_MRAD[k] for k in t.held_tips)} mrad (grasp check)")
            return
        if not t.settled(now) or now - t.phase_us < CHECK_POSE_US:
            return
        centre, k = t.check_waist
        if k + 1 < len(CHECK_WAIST_MRAD):  # the next waist offset: the gripper moves
            t.check_waist = (centre, k + 1)
            t.set_arm(now, *t.arm[2:5], centre + CHECK_WAIST_MRAD[k + 1])
            t.trust_from_us = t.move_done_us
            t.phase_us = t.move_done_us
            return
        if not t.check_seen and t.close_by not in CLOSES_ON_SIGHT:
            # a blind grasp where the camera does not see the object: its sighting before
            # counts no more, the next grasp goes on a new one (docs/task.md)
            t.object_sighted = False
        self.missed(t, now, "no evidence of the object in the gripper")


GRASP = GraspStates()
