"""State behaviours of the task (host.task): entry actions and per-step handlers.

A mixin of :class:`host.task.Task`; see that module for the machine.  Everything is integer
(mm, mrad, us, Q4 mm positions); the object estimate is kept in the odometry frame so it
survives the base moving while the object is out of view (000 §III.B.2: "the encoder
information is used and only the waist joint rotates accordingly to re-find the object").
"""

from __future__ import annotations

from mobigrasp.host import kinematics
from mobigrasp.host.control.fuzzy import FuzzyParams
from mobigrasp.host.fixedpoint import atan2_mrad, isqrt
from mobigrasp.host.planning.bezier000 import Params000
from mobigrasp.host.posture import distribute_alpha
from mobigrasp.host.search import ArmSearch, SearchParams
from mobigrasp.host.task_drive import (
    close_in,
    escape_001,
    make_fuzzy,
    make_pose,
    plan_follower,
    planner_params_001,
    start_001,
    straight_clear_001,
    turn_in_place,
    update_001,
)
from mobigrasp.host.task_grasp import GraspStates
from mobigrasp.host.task_sense import (
    CROSS_SPACING_MM_Q4,
    bearing_mrad,
    d_pixel_px,
)
from mobigrasp.host.task_wander import detour_step, seen_there_before, start_detour, wander_step
from mobigrasp.host.vision import registry

HOME_ARM = (0, 0, -1571, -1571, 1571, 0)  # gripper open, roll 0, camera looking down
SIGHTING_MAX_TURN_MRAD_S = 500  # 001 APPROACH: sightings taken while turning faster are not used
ADJUST_EARLY_MM_001 = 700  # 001 APPROACH: ADJUST from this close with the object in view
ADJUST_EARLY_FRESH_US = 300_000  # ... seen this recently


def _wrap(a: int) -> int:
    return (a + 3142) % 6283 - 3142


class TaskStates(GraspStates):
    """Entry actions ``enter_<STATE>`` and handlers ``do_<STATE>`` of the task."""

    def init_states(self, now_us: int) -> None:
        self.arm = list(HOME_ARM)
        self.joints = tuple(HOME_ARM)
        self.gripper = 0
        self.wheels = (0, 0)
        self.entry_pending = True
        self.failure = None
        self.search = None
        self.turn_from = None
        self.wander_from = None
        self.obj = None  # odometry-frame (x_mm, y_mm) of the object
        self.obj_seen_us = now_us
        self.follower = None
        self.plan_obj = None
        self.plan_us = now_us
        self.plan_attempts = 0
        self.fuzzy = None
        self.move_done_us = now_us
        self.phase = ""
        self.phase_us = now_us
        self.precise_steps = 0
        self.last_pose = (0, 0, 0, 0)
        self.arm_hist: list = []
        self.pose_hist: list = []
        self.confirm_until = None
        self.confirm_failed = None
        self.sighting = None  # odometry place of the last unconfirmed sighting (000/001)
        self.detour = None  # 001: a drive aside after no feasible curve (host.task_wander)
        self.detours = 0
        self.detour_side = 0  # 001: +1 the detours go round left of the object's bearing
        self.trust_from_us = 0
        self.plus_odom = None
        self.replanner = None
        self.grasp_xy_q4 = None
        self.grasp_alpha = 0 if self.method == "002" else kinematics.ALPHA_DOWN_MRAD
        self.e_mrad = 0
        self.prev_e = None
        self.blind = None  # 002: (odometry bearing of the marker, x_mm, y_mm, reach_mm)
        self.e_dpx = None  # 002: d_pixel of the search's sighting

    # --- SEARCH -------------------------------------------------------------------------------
    def enter_SEARCH(self, now: int, inp) -> None:
        self.search = ArmSearch(SearchParams(**self.p.search), self.arm[2], self.arm[5], now)
        self.turn_from = None
        self.wander_from = None
        self.gripper = 0
        if self.p.object_xy_mm and self.obj is None and self.counters["lost"] == 0:
            # 001 §II: the object position P_i is given; plan toward it, vision refines it
            self.obj = tuple(self.p.object_xy_mm)
            self.obj_seen_us = now
            self.go(now, "APPROACH", f"object position given: {self.obj} mm")

    def _found(self, now: int, inp, name: str, det) -> bool:
        """The search detector's result gives a usable object (000/001) or bearing (002)."""
        if self.method != "002":
            return self.see_object(now, inp, name, det)
        joints = self._at(self.arm_hist, now - self.p.frame_latency_us)[1] \
            if self.arm_hist else tuple(self.arm)
        try:
            e = bearing_mrad(det, joints[5], self.cam)
        except (ValueError, TypeError):
            self.counters["bad_detections"] += 1
            return False
        if e is None:
            return False
        self.e_mrad, self.obj_seen_us = e, now
        self.e_dpx = d_pixel_px(det)
        return True

    def _found_why(self) -> str:
        if self.method == "002":
            return f"double cross seen at e = {self.e_mrad} mrad"
        return f"radial symbol seen, object at {self.obj} mm"

    def do_SEARCH(self, now: int, inp, dets: dict) -> None:
        name = "double_cross" if self.method == "002" else "radial_symbol"
        det = dets.get(name)
        if self.confirm_until is not None:
            self.wheels = (0, 0)
            # holding the pose of the frame that showed the object: see it again, settled
            if det is not None and now >= self.move_done_us + self.p.frame_latency_us \
                    and self._found(now, inp, name, det):
                self.confirm_until = None
                self.go(now, "APPROACH", self._found_why() + " (confirmed)")
                return
            if now < self.confirm_until:
                return
            self.confirm_until = None  # not seen again: resume the pattern
            self.confirm_failed = tuple(self.arm)
            self.sighting = self.obj if self.method != "002" else None
            self.search.restart_dwell(now)
        elif det is not None and (self.search.wandering or not self.search.turning) \
                and self._found(now, inp, name, det):
            if seen_there_before(self):
                self.go(now, "APPROACH", self._found_why() + " (seen twice at that place)")
                return
            held = self._at(self.arm_hist, now - self.p.frame_latency_us)[1] \
                if self.arm_hist else tuple(self.arm)
            if held == self.confirm_failed:  # that pose was tried: the frame is a newer one
                held = tuple(self.arm)
            self.set_arm(now, *held[2:6], th1=held[1])
            self.confirm_until = self.move_done_us + self.p.confirm_us
            self.note(search_seen=self._found_why())
            return
        cmd = self.search.step(now)
        self.set_arm(now, cmd.theta2_mrad, cmd.theta3_mrad, cmd.theta4_mrad, cmd.theta5_mrad, 0)
        if cmd.drive_mm:
            wander_step(self, now, inp, cmd)
            return
        if not cmd.base_turn_mrad:
            self.wheels = (0, 0)
            return
        if self.turn_from is None:
            self.turn_from = inp.heading_mrad
            self.note(base_turn_mrad=cmd.base_turn_mrad, search_cycle=cmd.cycle)
        if abs(_wrap(inp.heading_mrad - self.turn_from)) >= cmd.base_turn_mrad:
            self.search.base_turn_done(now)
            self.turn_from = None
            self.wheels = (0, 0)
        else:
            self.wheels = turn_in_place(1 if cmd.base_turn_mrad > 0 else -1,
                                        self.p.turn_wheel_mmps)

    # --- APPROACH -----------------------------------------------------------------------------
    def enter_APPROACH(self, now: int, inp) -> None:
        self.follower, self.plan_attempts = None, 0
        if self.method == "002":
            self.fuzzy = make_fuzzy(FuzzyParams(**self.p.fuzzy))
            # the search's sighting is the first bearing to steer on if the next frames miss
            self._remember_bearing_002(inp, self.e_mrad, self.e_dpx)

    def _plan(self, now: int, inp) -> None:
        if self.method == "001" and self.replanner is not None and self.obj == self.plan_obj:
            # same object: the replanner keeps its remembered regions and slows down (replan.py)
            dec, follower, ops = update_001(self.replanner, now, inp.x_mm, inp.y_mm,
                                            inp.heading_mrad, inp.v_mmps, inp.sonar_mm)
            detail = {"planner": "001", "reason": dec.reason}
            if dec.curve is not None:
                detail["best_ctrl"] = [list(map(float, row)) for row in dec.curve.ctrl]
        elif self.method == "001":
            self.replanner, follower, ops, detail = start_001(
                now, inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps, self.obj, inp.sonar_mm,
                planner_params_001(self.p))
        else:
            pp = Params000(**{"standoff_m": self.p.approach_standoff_mm / 1000, **self.p.planner})
            follower, ops, detail = plan_follower(self.method, now, inp.x_mm, inp.y_mm,
                                                  inp.heading_mrad, inp.v_mmps, self.obj,
                                                  inp.sonar_mm, pp)
        self.charge(ops)
        self.counters["plans"] += 1
        self.note(plan=detail)
        self.plan_us, self.plan_obj = now, self.obj
        if follower is not None:
            self.follower = follower
            return
        if "already" in detail["reason"]:
            self.go(now, "ADJUST", f"no path needed: {detail['reason']}")
            return
        self.plan_attempts += 1
        if self.plan_attempts >= self.p.max_plan_attempts:
            x, y = self.obj_platform(inp)
            dist = isqrt(x * x + y * y) // 16
            # 001: an echo straight ahead well short of the object (its own echo is ~170 mm
            # short of the waist distance: ring 70 mm ahead of the waist plus its radius)
            n = len(inp.sonar_mm)
            echo = self.method == "001" and n >= 3 and 0 < int(inp.sonar_mm[n // 2]) < dist - 300
            # 001: nor when the straight way to the object crosses an infeasible region (eq.
            # (16)): an obstacle beside the line, unseen by the front sonar, was grazed
            # (random 001 seed 1014)
            echo = echo or (self.method == "001" and not self._straight_clear_001(inp, dist))
            if dist <= self.p.direct_max_mm and not echo:  # the close approach can do it
                self.go(now, "ADJUST", f"no feasible curve ({detail['reason']}); object "
                        f"{dist} mm away: direct approach")
            elif self.method == "001" and self.detours < self.p.max_detours:
                # 001: obstacles across the way and no curve around them from here: drive
                # aside through free sonar space, then plan again (host.task_wander)
                self.detours += 1
                head, ops = escape_001(self.replanner, inp.x_mm, inp.y_mm, inp.heading_mrad,
                                       inp.sonar_mm, self.obj, self.p.detour_mm,
                                       self.detour_side)
                self.charge(ops)
                if head is not None and not self.detour_side:  # keep to the first one's side
                    off = _wrap(head - atan2_mrad(self.obj[1] - inp.y_mm, self.obj[0] - inp.x_mm))
                    self.detour_side = (off > 0) - (off < 0)
                self.detour = start_detour(inp, self.obj, self.p.detour_clear_mm, head)
                self.plan_attempts, self.follower = 0, None
                self.note(detour=dict(self.detour), detour_count=self.detours)
            else:  # (not the direct approach into an echo: it collided, random 001 seeds)
                self.fail(now, f"no feasible approach path: {detail['reason']}")

    def _turning_fast(self, now: int, inp) -> bool:
        """001: the base turned faster than SIGHTING_MAX_TURN_MRAD_S over the last frame
        latency. Ours: the frame's capture time is known only as ``frame_latency_us`` ago (the
        vision time varies by 10-25 ms), and the arm history holds servo targets, not where the
        lagging servos were; at 1.5 rad/s (a tight 001 curve at low speed, a_t = v²κ allows it)
        that put a sighting 0.4 m away 60 mm off (random 001 seed 5017), and the grasp on it
        missed. The given P_i or an earlier sighting is kept instead."""
        if not self.pose_hist:
            return False
        then = self._at(self.pose_hist, now - self.p.frame_latency_us)
        dt = max(1, now - then[0])
        rate = abs(_wrap(inp.heading_mrad - then[3])) * 1_000_000 // dt
        return rate > SIGHTING_MAX_TURN_MRAD_S

    def _face_object(self, inp) -> bool:
        """Turn the base in place toward the object; True once it faces it (ours, not the
        papers': a curve from a standstill facing away can violate A_max or R_min)."""
        x, y = self.obj_platform(inp)
        bearing = atan2_mrad(x, y + self.p.mount_forward_mm * 16)  # seen from the axle
        if abs(bearing) <= self.p.bearing_tol_mrad:
            self.wheels = (0, 0)
            return True
        self.wheels = turn_in_place(-1 if bearing > 0 else 1, self.p.turn_wheel_mmps)
        return False

    def do_APPROACH(self, now: int, inp, dets: dict) -> None:
        if self.method == "002":
            self._approach_002(now, inp, dets)
            return
        det = dets.get("radial_symbol")
        if det is not None and not (self.method == "001" and self._turning_fast(now, inp)):
            self.see_object(now, inp, "radial_symbol", det)
        moved = (self.plan_obj is not None and isqrt((self.obj[0] - self.plan_obj[0]) ** 2 + (
            self.obj[1] - self.plan_obj[1]) ** 2) > self.p.replan_shift_mm)
        due = self.method == "001" and now - self.plan_us >= self.p.replan_period_us
        if due and self.follower is not None and not moved and self.replanner is not None:
            # 001 §III.E: the sonars see the rest of the path blocked -> replan from here
            dec, follower, ops = update_001(self.replanner, now, inp.x_mm, inp.y_mm,
                                            inp.heading_mrad, inp.v_mmps, inp.sonar_mm)
            self.charge(ops)
            self.plan_us = now
            if dec.replanned:
                self.follower = follower
                self.counters["plans"] += 1
                self.note(replan=dec.reason, plan={
                    "planner": "001", "reason": dec.reason,
                    "best_ctrl": [list(map(float, row)) for row in dec.curve.ctrl]})
            elif dec.blocked and dec.curve is not None:
                self.note(replan=dec.reason)  # blocked far ahead, no update yet: path kept
            elif dec.curve is None:
                self.follower = None  # nothing feasible: stop; the next step plans afresh
                self.note(replan=dec.reason)
                self.wheels = (0, 0)
                return
        elif self.follower is None or moved:
            if (self.method == "001" and self.replanner is None
                    and now - self.entered_us < self.p.sonar_sweep_us):
                self.wheels = (0, 0)  # 001: the first plan waits for one full sonar sweep
                return
            if self.detour is not None:
                if not detour_step(self, inp):
                    return
                self.detour, self.plan_us = None, now  # done: stop, then plan afresh from here
            if self.follower is None and self.method == "001" and self.replanner is not None and (
                    now - self.plan_us < 500_000 or abs(inp.v_mmps) > 30):
                self.wheels = (0, 0)  # 001: stop first, then replan from standstill
                return
            if self.follower is None and self.plan_attempts and not self._face_object(inp):
                return  # no feasible curve from here: face the object in place, then replan
            self._plan(now, inp)
            if self.state != "APPROACH" or self.follower is None:
                self.wheels = (0, 0)
                return
        self.look_at_object(inp)
        x, y = self.obj_platform(inp)
        dist = isqrt(x * x + y * y) // 16
        cmd = self.follower.step(now, make_pose(inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps))
        self.wheels = (cmd.left_mm_s, cmd.right_mm_s)
        if self.method == "001" and cmd.left_mm_s + cmd.right_mm_s < 0:
            # ours: 001's sonar ring (S_1..S_k_s, ±π/2 about the heading) sees nothing behind
            # the base, so it never backs up: a curve whose reference fell behind (a tight
            # loop) made the follower reverse into an obstacle out of view (random 001 seed
            # 7009); it turns on the spot instead and the sonar check replans from there
            turn = (cmd.right_mm_s - cmd.left_mm_s) // 2
            self.wheels = (-turn, turn)
        if cmd.done or dist <= self.p.grasp_r_mm + 100:
            self.go(now, "ADJUST", f"path followed (error {cmd.error_mm} mm), object {dist} mm "
                    f"from the waist")
        elif self.method == "001" and self._adjust_early_001(now, inp, dist):
            self.go(now, "ADJUST", f"object in view {dist} mm from the waist, nothing in the "
                    f"way: vision-based adjustment (000 §III.B) from here")

    def _adjust_early_001(self, now: int, inp, dist: int) -> bool:
        """001: hand the last part of the curve to 000's vision-based approaching adjustment
        (§III.B) while the object is still in the camera's view. Ours: the curve ends on the
        grasp circle (eqs. (5)-(6) of 001, l_e ~ 0.23 m), where the long 001 arm's camera looks
        over the object top and sees neither the dual "+" nor the radial symbol; ADJUST then
        finished on the last sightings and odometry (12-14 mm off in paper001-sim1/sim2, the
        spoke never found). Only with a sighting in the last ``ADJUST_EARLY_FRESH_US`` and the
        straight way to the object clear (the close approach drives straight at it)."""
        if not (self.p.grasp_r_mm + 100 < dist <= ADJUST_EARLY_MM_001):
            return False
        if now - self.obj_seen_us > ADJUST_EARLY_FRESH_US:
            return False
        return self._straight_clear_001(inp, dist)

    def _straight_clear_001(self, inp, dist: int) -> bool:
        """001: the close approach's straight way to the object (``dist`` from the waist, to
        stop ``grasp_r_mm`` short) misses the infeasible regions of eq. (16) (host.task_drive)."""
        if self.replanner is None:
            return False
        clear, ops = straight_clear_001(self.replanner, inp.x_mm, inp.y_mm, inp.heading_mrad,
                                        inp.sonar_mm, self.obj, dist - self.p.grasp_r_mm)
        self.charge(ops)
        return clear

    def _approach_002(self, now: int, inp, dets: dict) -> None:
        rc = dets.get("red_cylinder")
        d_px = d_pixel_px(rc)
        if d_px is not None and self.see_object(now, inp, "red_cylinder", rc) and \
                d_px >= self.p.cylinder_near_px:
            self.go(now, "ADJUST", f"red cylinder seen, d_pixel = {d_px} px")
            return
        if self.obj is not None:  # the cylinder stands before the marker: do not run it over
            x, y = self.obj_platform(inp)
            dist = isqrt(x * x + y * y) // 16
            if dist <= self.p.grasp_r_mm + 150:
                self.go(now, "ADJUST", f"red cylinder estimated {dist} mm from the waist")
                return
        if not dets:
            return  # no new frame: keep the wheels as they are
        dc = dets.get("double_cross")
        yaw = self._at(self.arm_hist, now - self.p.frame_latency_us)[1][5] \
            if self.arm_hist else self.arm[5]  # the waist when the frame was taken
        try:
            e = bearing_mrad(dc, yaw, self.cam) if dc is not None else None
            if e is None and rc is not None:
                # the double cross out of reach but the cylinder in view (far, a few px wide):
                # steer on the cylinder's column, or the robot would stand still while the
                # cylinder's sightings keep LOST away
                u_c = registry.check("red_cylinder", rc).u_c_q4
                e = yaw + atan2_mrad(u_c - self.cam.u0_px * 16, self.cam.f_px * 16)
        except (ValueError, TypeError):
            self.counters["bad_detections"] += 1
            e = None
        if e is None and self._approach_blind_002(now, inp):
            return
        if e is None and now - self.obj_seen_us >= self.p.lost_timeout_us:
            self.go(now, "LOST", f"double cross not seen for {now - self.obj_seen_us} us")
            return
        dc_px = d_pixel_px(dc) if dc is not None else None
        if dc_px is not None and dc_px >= self.p.cross_near_px and \
                self.see_object(now, inp, "double_cross", dc):
            # near, the cylinder may be below the level look while the board is big in view:
            # its estimate from the crosses ends the approach (random 002 seed 1031 ran into it)
            x, y = self.obj_platform(inp)
            dist = isqrt(x * x + y * y) // 16
            if dist <= self.p.grasp_r_mm + 150:
                self.go(now, "ADJUST", f"crosses {dc_px} px apart: red cylinder estimated "
                        f"{dist} mm from the waist")
                return
        cmd = self.fuzzy.step(now, e, None)
        if e is not None:
            self.obj_seen_us = now
            self._remember_bearing_002(inp, e, dc_px)
            self._track_marker_002(now, dc, e)
        self.wheels = (cmd.left_mm_s, cmd.right_mm_s)
        ec = None
        if e is not None and self.prev_e is not None and now > self.prev_e[0]:
            ec = (e - self.prev_e[1]) * 1_000_000 // (now - self.prev_e[0])
        self.prev_e = (now, e) if e is not None else None
        self.note(fuzzy={"e_mrad": e, "e_c_mrad_s": ec, "u_mrad": cmd.u_mrad,
                         "wheels_mmps": list(self.wheels)})

    def _remember_bearing_002(self, inp, e: int, d_px: int | None) -> None:
        """The bearing to steer on blind should the next frames miss the marker, and how far:
        at most ``blind_approach_mm``, and ``blind_keep_mm`` short of the board's distance by
        the crosses' spacing. Near, a lost marker has left the view (the base turned, or it is
        below the look): driving on blind went past the object (random 002 seed 1031)."""
        self.blind = None
        if d_px is None or d_px <= 0:
            return
        board_mm = CROSS_SPACING_MM_Q4 * self.cam.f_px // (16 * d_px)
        reach = min(self.p.blind_approach_mm, board_mm - self.p.blind_keep_mm)
        if reach > 0:
            self.blind = (inp.heading_mrad - e, inp.x_mm, inp.y_mm, reach)

    def _approach_blind_002(self, now: int, inp) -> bool:
        """No marker in this frame: steer on the bearing it was last seen at, by odometry, for
        up to the reach of :meth:`_remember_bearing_002` and ``blind_approach_us``; True while
        doing so.

        Ours, not 002's (its fuzzy loop assumes the marker always in view): beyond ~2.5 m the
        crosses are ~10 px wide and the detector misses them in most frames, although the
        search (which holds still and confirms) did see them; standing still there, as before,
        ended in LOST -> SEARCH -> LOST until the object was given up (random 002 runs)."""
        if self.blind is None:
            return False
        goal, x0, y0, reach = self.blind
        if (isqrt((inp.x_mm - x0) ** 2 + (inp.y_mm - y0) ** 2) >= reach
                or now - self.obj_seen_us >= self.p.blind_approach_us):
            return False
        e = _wrap(inp.heading_mrad - goal)  # right positive, like the camera's e
        cmd = self.fuzzy.step(now, e, None)
        self.wheels = (cmd.left_mm_s, cmd.right_mm_s)
        self.set_arm(now, self.arm[2], self.arm[3], self.arm[4], max(-800, min(800, e)))
        self.prev_e = None
        self.note(fuzzy={"e_mrad": e, "e_c_mrad_s": None, "u_mrad": cmd.u_mrad,
                         "wheels_mmps": list(self.wheels), "blind": True})
        return True

    def _track_marker_002(self, now: int, det, e: int) -> None:
        """Keep the marker in view: the waist faces it (theta5 = e) and d_alpha, the pitch of
        its pixel row off the optical centre, is shared by eq. (10) of 000 (host.posture)."""
        th5 = max(-800, min(800, e))
        # no double cross (steered on the red cylinder): the pitch is kept
        vm = det.vm_q4 if isinstance(det, registry.row("double_cross").result_type()) else None
        d2 = d3 = d4 = 0
        if vm is not None:
            d_alpha = -atan2_mrad(vm - self.cam.v0_px * 16, self.cam.f_px * 16)
            cap = self.p.posture_step_mrad
            d_alpha = max(-cap, min(cap, d_alpha))
            d2, d3, d4 = distribute_alpha(d_alpha, *self.arm[2:5], self.posture_params(cap))
        self.set_arm(now, self.arm[2] + d2, self.arm[3] + d3, self.arm[4] + d4, th5)

    # --- ADJUST -------------------------------------------------------------------------------
    def enter_ADJUST(self, now: int, inp) -> None:
        """Close-look posture (ours): shoulder up, elbow bent, so that theta2 alone (000's
        k_theta2 = 1) can pitch the camera down to the object at arm's length; alpha is kept."""
        th3, th4 = self.p.adjust_theta3_mrad, self.p.adjust_theta4_mrad
        alpha = self.arm[2] + self.arm[3] + self.arm[4]
        self.set_arm(now, alpha - th3 - th4, th3, th4, self.arm[5])
        self.trust_from_us = self.move_done_us
        self.obj_seen_us = max(self.obj_seen_us, self.move_done_us)  # LOST counts from then

    def do_ADJUST(self, now: int, inp, dets: dict) -> None:
        name = "red_cylinder" if self.method == "002" else "dual_plus"
        det = dets.get(name)
        if det is not None:
            self.see_object(now, inp, name, det)
        elif dets.get("radial_symbol") is not None:  # the dual "+" out of its range: the rings
            self.see_object(now, inp, "radial_symbol", dets["radial_symbol"])
        x, y = self.obj_platform(inp)
        if self.method == "002" and det is not None:
            d_px = d_pixel_px(det)
            dist = isqrt(x * x + y * y) // 16
            # T_d of 002 says "in the workspace" for 002's camera placement; ours also needs the
            # estimate within reach, else it creeps on (close_in below)
            if d_px is not None and d_px > self.p.t_d_px and \
                    dist <= self.p.grasp_r_mm + self.p.grasp_r_tol_mm:
                self.wheels = (0, 0)
                self.go(now, "ROUGH_GRASP", f"d_pixel = {d_px} px > T_d = {self.p.t_d_px}")
                return
        # 002 §1: slowly on toward the cylinder until d_pixel > T_d; the estimate stops it at
        # grasp_r_mm (clear of the footprint) should the rings never be resolved
        vmax = self.p.slow_mmps if self.method == "002" else self.p.adjust_vmax_mmps
        wheels, done, d = close_in((x, y), self.p.grasp_r_mm, self.p.grasp_r_tol_mm,
                                   self.p.bearing_tol_mrad, vmax)
        self.note(adjust=d)
        unseen = now - self.obj_seen_us
        if unseen >= self.p.lost_timeout_us and abs(d["err_mm"]) > self.p.blind_finish_mm:
            self.wheels = (0, 0)
            self.go(now, "LOST", f"{name} not seen for {unseen} us, {d['dist_mm']} mm away")
            return
        self.look_at_object(inp)
        self.wheels = wheels
        if done:
            self.go(now, "ROUGH_GRASP", f"object {d['dist_mm']} mm ahead of the waist, "
                    f"bearing {d['bearing_mrad']} mrad")

    # --- LOST ---------------------------------------------------------------------------------
    def enter_LOST(self, now: int, inp) -> None:
        self.wheels = (0, 0)
        self.counters["lost"] += 1
        if self.counters["lost"] > self.p.max_lost:
            self.fail(now, f"object lost {self.counters['lost']} times")

    def do_LOST(self, now: int, inp, dets: dict) -> None:
        self.wheels = (0, 0)
        if now - self.entered_us >= self.p.lost_hold_us:
            self.go(now, "SEARCH", "platform stopped: searching with the arm (000 Fig. 5)")
