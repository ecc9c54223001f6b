"""SEARCH and LOST: the arm search of 000 Fig. 5, its wander and sighting memory, the stop.

SEARCH runs host.search's pattern (arm sweeps, base turns between cycles) and looks for the
method's search detector (``Method.search_detector``); a sighting is held still and confirmed
in a second frame before APPROACH. The wander is the caller's half of host.search's wandering
search (000 §II: the robot "firstly wanders in the environment to search object"): drive
straight ahead on odometry for the leg the search asks, stop short when a front sonar sees
something. The sighting memory lets a sighting near the edge of the radial symbol's range count
when it is seen again at the same place. LOST stops the platform and searches again (000
§III.B.2). Integer mm / us; no I/O and no clock. Each handler takes the task ``t`` first.
"""

from __future__ import annotations

from mobigrasp.host.fixedpoint import atan2_mrad, isqrt
from mobigrasp.host.search import ArmSearch, SearchParams
from mobigrasp.host.task.drive import turn_in_place, wrap_mrad
from mobigrasp.host.task.sense import odom_to_platform_q4
from mobigrasp.host.task.sonar_guard import blocked_ahead, drive_detour, free_heading_nearest

# the look at a far sighting once driven near it: the waist at its bearing, then this far to
# either side (a frame taken while the waist swept puts the estimate up to ~0.5 rad off the
# symbol's bearing), each pose held for FAR_LOOK_FRAMES frames once settled (docs/task.md
# "000: a far sighting driven to")
FAR_LOOK_OFFSETS_MRAD = (0, 350, -350, 700, -700)
FAR_LOOK_FRAMES = 2


class SearchStates:
    """Entry actions and steps of SEARCH and LOST."""

    # --- SEARCH -------------------------------------------------------------------------------
    def enter_SEARCH(self, t, now: int, inp) -> None:
        sp, th2s, th5s = SearchParams(**t.p.search), t.arm[2], t.arm[5]
        lost = t.rules.lost_search(t, sp, t.lost_in) if t.lost_in else None
        if lost is not None:
            sp, th2s, th5s = lost
            t.note(lost_search={"lost_in": t.lost_in, "theta2s_mrad": th2s,
                                "theta5s_mrad": th5s, "d_theta2_mrad": sp.d_theta2_mrad})
        t.lost_in = None
        t.search = ArmSearch(sp, th2s, th5s, now)
        t.turn_from = None
        t.wander_from = t.wander_round = t.wander_look = None
        t.far = None
        t.gripper = 0
        if t.p.object_xy_mm and t.obj is None and t.counters["lost"] == 0:
            # 001 §II: the object position P_i is given; plan toward it, vision refines it
            t.obj = tuple(t.p.object_xy_mm)
            t.obj_seen_us = now
            t.go(now, "APPROACH", f"object position given: {t.obj} mm")

    def do_SEARCH(self, t, now: int, inp, dets: dict) -> None:
        if t.rules.search_back_off(t, now, inp, dets):
            return
        name, det = t.rules.search_sighting(dets)
        if t.confirm_until is not None:
            t.wheels = (0, 0)
            # holding the pose of the frame that showed the object: see it again, settled
            if det is not None and now >= t.move_done_us + t.p.frame_latency_us \
                    and t.rules.found(t, now, inp, name, det):
                t.confirm_until = None
                t.go(now, "APPROACH", t.rules.found_why(t) + " (confirmed)")
                return
            if now < t.confirm_until:
                return
            t.confirm_until = None  # not seen again: resume the pattern
            t.confirm_failed = tuple(t.arm)
            t.sighting = t.obj if t.rules.keeps_sightings else None
            t.search.restart_dwell(now)
            was_far, t.far = t.far is not None, None
            if not self.far_sighting(t, inp) and was_far:
                self.rejoin(t, now, inp)
        elif det is not None and t.rules.found(t, now, inp, name, det):
            # seen at a dwell, on a wander leg or while the base turns: stop and confirm
            t.wheels = (0, 0)
            if self.seen_there_before(t):
                t.go(now, "APPROACH", t.rules.found_why(t) + " (seen twice at that place)")
                return
            held = t.arm_at(now - t.p.frame_latency_us)
            if held == t.confirm_failed:  # that pose was tried: the frame is a newer one
                held = tuple(t.arm)
            t.set_arm(now, *held[2:6], th1=held[1])
            t.confirm_until = t.move_done_us + t.p.confirm_us
            t.note(search_seen=t.rules.found_why(t))
            return
        if t.far is not None:
            if self.far_step(t, now, inp):
                return
            t.far = None
            self.rejoin(t, now, inp)
        cmd = t.search.step(now, (inp.x_mm, inp.y_mm, inp.heading_mrad))
        why = t.rules.search_gives_up(t)
        if why:
            t.fail(now, why)
            return
        t.set_arm(now, cmd.theta2_mrad, cmd.theta3_mrad, cmd.theta4_mrad, cmd.theta5_mrad, 0)
        if cmd.drive_mm:
            self.wander_step(t, now, inp, cmd)
            return
        if not cmd.base_turn_mrad:
            t.wheels = (0, 0)
            return
        if t.turn_from is None:
            t.turn_from = inp.heading_mrad
            t.note(base_turn_mrad=cmd.base_turn_mrad, search_cycle=cmd.cycle)
        if abs(wrap_mrad(inp.heading_mrad - t.turn_from)) >= abs(cmd.base_turn_mrad):
            t.search.base_turn_done(now)
            t.turn_from = None
            t.wheels = (0, 0)
        else:
            t.wheels = turn_in_place(1 if cmd.base_turn_mrad > 0 else -1,
                                     t.p.search_turn_wheel_mmps or t.p.turn_wheel_mmps)

    # --- LOST ---------------------------------------------------------------------------------
    def enter_LOST(self, t, now: int, inp) -> None:
        t.wheels = (0, 0)
        t.counters["lost"] += 1
        if t.counters["lost"] > t.p.max_lost:
            t.fail(now, f"object lost {t.counters['lost']} times")

    def do_LOST(self, t, now: int, inp, dets: dict) -> None:
        t.wheels = (0, 0)
        if now - t.entered_us >= t.p.lost_hold_us:
            t.go(now, "SEARCH", "platform stopped: searching with the arm (000 Fig. 5)")

    def seen_there_before(self, t) -> bool:
        """000/001: a sighting that could not be confirmed, seen again at the same odometry place
        (within ``sighting_match_mm``), is the object: near the edge of the symbol's range
        (~1.1 m) single frames come and go, and two from different poses agreeing are
        evidence enough to approach (the approach sees it better as it comes closer)."""
        if t.sighting is None or t.obj is None:
            return False
        dx, dy = t.obj[0] - t.sighting[0], t.obj[1] - t.sighting[1]
        return dx * dx + dy * dy <= t.p.sighting_match_mm * t.p.sighting_match_mm

    # --- a far sighting: drive near it and look -------------------------------------------------
    @staticmethod
    def _sighting_platform(t, inp) -> tuple[int, int, int]:
        """The unconfirmed sighting from the base: (waist bearing mrad, right positive; bearing
        from the axle; distance from the axle mm)."""
        x, y = odom_to_platform_q4(inp.x_mm, inp.y_mm, inp.heading_mrad, t.p.mount_forward_mm,
                                   t.sighting[0], t.sighting[1])
        axle_y = y + t.p.mount_forward_mm * 16
        return atan2_mrad(x, y), atan2_mrad(x, axle_y), isqrt(x * x + axle_y * axle_y) // 16

    def far_sighting(self, t, inp) -> bool:
        """A sighting not seen again at rest, farther than ``sighting_approach_mm`` +
        ``sighting_match_mm`` from the axle (near the edge of the symbol's range, where single
        frames come and go): drive near it before dropping it (:meth:`far_step`). At most
        ``sighting_approaches`` a run. The sighting alone is not the object: what it finds is
        confirmed as any sighting is. True if the drive starts."""
        if not t.p.sighting_approach_mm or t.sighting is None \
                or t.far_count >= t.p.sighting_approaches:
            return False
        _, bearing, dist = self._sighting_platform(t, inp)
        if dist <= t.p.sighting_approach_mm + t.p.sighting_match_mm:
            return False
        t.far_count += 1
        t.far = ("turn", 0, 0)
        t.note(far_sighting={"bearing_mrad": bearing, "dist_mm": dist, "n": t.far_count,
                             "x_mm": t.sighting[0], "y_mm": t.sighting[1]})
        return True

    def far_step(self, t, now: int, inp) -> bool:
        """One step of the drive to a far sighting (True while under way): turn on the spot
        toward it, drive straight at ``wander_mmps`` until ``sighting_approach_mm`` from it
        (stopped short, as a wander leg, when a front sonar sees something within
        ``wander_clear_mm``), then look at it from there: the waist at its bearing and
        FAR_LOOK_OFFSETS_MRAD beside it, each held for FAR_LOOK_FRAMES settled frames. The
        camera looks toward it throughout; a sighting on the way is confirmed as any."""
        phase, k, since = t.far
        if phase != "look":  # the camera follows the sighting's bearing
            self._far_arm(t, now, inp, 0)
        if phase == "turn":
            _, bearing, dist = self._sighting_platform(t, inp)
            if abs(bearing) > t.p.bearing_tol_mrad:
                t.wheels = turn_in_place(-1 if bearing > 0 else 1, t.p.turn_wheel_mmps)
                return True
            phase = "drive"
            t.far = (phase, 0, dist)
        if phase == "drive":
            dist = self._sighting_platform(t, inp)[2]
            if dist > t.p.sighting_approach_mm and not self.front_blocked(t, inp) \
                    and dist <= t.far[2]:
                t.wheels = (t.p.wander_mmps, t.p.wander_mmps)
                return True
            t.note(far_stop_mm=dist)
            t.wheels = (0, 0)
            t.far = ("look", 0, now)
            return True
        t.wheels = (0, 0)  # a look: frames taken from ``since`` on, the servos settled
        if now < max(t.move_done_us, since) + t.p.frame_latency_us \
                + FAR_LOOK_FRAMES * t.search.params.frame_period_us:
            return True
        if k + 1 < len(FAR_LOOK_OFFSETS_MRAD):
            t.far = ("look", k + 1, now)
            self._far_arm(t, now, inp, FAR_LOOK_OFFSETS_MRAD[k + 1])
            return True
        return False

    def _far_arm(self, t, now: int, inp, off_mrad: int) -> None:
        """The search's far level, the waist at the sighting's bearing and ``off_mrad``."""
        sp = t.search.params
        waist = self._sighting_platform(t, inp)[0] + off_mrad
        t.set_arm(now, sp.coarse_theta2_mrad[0], sp.theta3_mrad, sp.theta4_mrad,
                  max(-sp.wander_theta5_mrad, min(sp.wander_theta5_mrad, waist)), 0)

    def rejoin(self, t, now: int, inp) -> None:
        """Back to the search's pattern after a drive off it (:meth:`far_step`)."""
        t.search.rejoin(now, (inp.x_mm, inp.y_mm, inp.heading_mrad))
        t.wander_from = t.turn_from = None
        t.wheels = (0, 0)

    @staticmethod
    def front_blocked(t, inp) -> bool:
        """A front sonar (the middle three) sees something within ``wander_clear_mm``."""
        n = len(inp.sonar_mm)
        front = [int(v) for v in inp.sonar_mm[max(0, n // 2 - 1):n // 2 + 2]] if n else []
        return any(0 < v < t.p.wander_clear_mm for v in front)

    def wander_step(self, t, now: int, inp, cmd) -> None:
        """Drive the search's wander straight ahead on odometry (000 §II "wanders in the
        environment"); stop short when a front sonar sees something within wander_clear_mm.
        A leg of the last ring so stopped goes round the obstacle when the search asks it
        (``round_tries``): toward the free sonar direction nearest its station, ``detour_mm``
        (the sonar guard's detour), then to the same station again, stopping only for
        something in its way (``blocked_ahead``), not for the obstacle beside it (docs/task.md
        "000: a ring's leg stopped by an obstacle")."""
        if t.wander_round is not None:
            if drive_detour(t, inp, t.wander_round):
                t.wander_round = None
                t.search.wander_resume(now)
            return
        if t.wander_look is not None:  # facing a cut symbol, then a cycle at rest there
            off = wrap_mrad(t.wander_look - inp.heading_mrad)
            if abs(off) > t.p.bearing_tol_mrad:
                t.wheels = turn_in_place(1 if off > 0 else -1, t.p.turn_wheel_mmps)
                return
            t.wheels = (0, 0)
            t.wander_look = None
            t.search.wander_look(now)
            return
        if t.wander_from is None:
            t.wander_from = (inp.x_mm, inp.y_mm)
            t.note(wander_mm=cmd.drive_mm, search_cycle=cmd.cycle)
        dx, dy = inp.x_mm - t.wander_from[0], inp.y_mm - t.wander_from[1]
        blocked = blocked_ahead(inp.sonar_mm) if t.search.passing \
            else self.front_blocked(t, inp)
        if dx * dx + dy * dy >= cmd.drive_mm * cmd.drive_mm or blocked:
            t.note(wander_done_mm=isqrt(dx * dx + dy * dy), wander_blocked=blocked)
            t.wander_from = None
            t.wheels = (0, 0)
            if not blocked:
                t.search.wander_done(now)
                return
            look = t.rules.search_cut_look(t, now)
            if look is not None:  # the object may be what stopped it: face it and look
                t.wander_look = look
                t.note(wander_look_mrad=wrap_mrad(look - inp.heading_mrad))
                return
            station = t.search.station_xy
            head = None if station is None else free_heading_nearest(inp, station,
                                                                     t.p.detour_clear_mm)
            if t.search.wander_blocked(now, head is not None):
                t.wander_round = {"heading_mrad": head, "drive": True, "from": None,
                                  "checked": True, "length_mm": t.p.detour_mm}
                t.note(wander_round_mrad=head)
        else:
            t.wheels = (t.p.wander_mmps, t.p.wander_mmps)


SEARCH = SearchStates()
