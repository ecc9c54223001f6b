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

from mobigrasp.host.fixedpoint import isqrt
from mobigrasp.host.search import ArmSearch, SearchParams
from mobigrasp.host.task.drive import turn_in_place, wrap_mrad


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
        t.wander_from = None
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

    def wander_step(self, t, now: int, inp, cmd) -> None:
        """Drive the search's wander straight ahead on odometry (000 §II "wanders in the
        environment"); stop short when a front sonar sees something within wander_clear_mm."""
        if t.wander_from is None:
            t.wander_from = (inp.x_mm, inp.y_mm)
            t.note(wander_mm=cmd.drive_mm, search_cycle=cmd.cycle)
        dx, dy = inp.x_mm - t.wander_from[0], inp.y_mm - t.wander_from[1]
        n = len(inp.sonar_mm)
        front = [int(v) for v in inp.sonar_mm[max(0, n // 2 - 1):n // 2 + 2]] if n else []
        blocked = any(0 < v < t.p.wander_clear_mm for v in front)
        if dx * dx + dy * dy >= cmd.drive_mm * cmd.drive_mm or blocked:
            t.note(wander_done_mm=isqrt(dx * dx + dy * dy), wander_blocked=blocked)
            t.search.wander_done(now)
            t.wander_from = None
            t.wheels = (0, 0)
        else:
            t.wheels = (t.p.wander_mmps, t.p.wander_mmps)


SEARCH = SearchStates()
