"""Paper 002's method: double cross, fuzzy approach, red cylinder, the level gripper.

SEARCH looks for the double cross (002 §2.1) and takes its bearing e; APPROACH steers with the
fuzzy controller on e (host.control.fuzzy: 35 rules, eq. (1) centroid, eq. (2) wheel law), the
waist facing the marker; ADJUST "slows down and goes straight with posture adjustment" (002 §1)
until the red cylinder's ring spacing d_pixel > T_d; ROUGH_GRASP goes to the pre-grasp point
with the gripper level by eq. (4), PRECISE_GRASP moves in to the axis and closes; the grasp
check of LIFT looks for the red cylinder still standing. Ours, not 002's: the approach steers on
the far red cylinder's column when the crosses are out of reach, drives on blind toward the
last bearing for a while when a frame misses the marker, and ends when the crosses, big in
view, place the cylinder near.
"""

from __future__ import annotations

from typing import Any

from mobigrasp.host import kinematics
from mobigrasp.host.control.fuzzy import FuzzyApproach, FuzzyParams
from mobigrasp.host.fixedpoint import atan2_mrad, isqrt
from mobigrasp.host.posture import distribute_alpha
from mobigrasp.host.task.drive import wrap_mrad
from mobigrasp.host.task.grasp import GRASP
from mobigrasp.host.task.method import Method
from mobigrasp.host.task.sense import (
    CAMERA_002,
    CROSS_SPACING_MM_Q4,
    bearing_mrad,
    d_pixel_px,
)
from mobigrasp.host.vision import registry
from mobigrasp.host.vision.double_cross import DoubleCrossResult

GRASP_ALPHAS_002 = (0, -100, -200, -280)  # horizontal first; the world accepts |alpha| < 0.3


class Method002(Method):
    """002: the hooks of the machine's states (host/task/method.py)."""

    name = "002"
    link_lengths_mm = (97.0, 89.0, 95.5)
    camera = CAMERA_002
    # the level gripper of 002 (eq. (4)) with theta2 <= 0 reaches the grasp point 50 mm above
    # the low shoulder only 230..275 mm ahead of the waist (pitch 0..-0.28 rad): stop the base
    # 255 +- 15 mm short and come in from 40 mm short of the axis
    param_defaults = {"h_shoulder_mm": 50, "object_top_mm": 120, "grasp_height_mm": 100,
                      "grasp_r_mm": 255, "grasp_r_tol_mm": 15, "pregrasp_back_mm": 40,
                      # the double cross stands upright, far: the paper's first cycle, then the
                      # level look (f = 350 px: 0.66 rad vertical field)
                      "search": {"dense_cycles": 1, "coarse_theta2_mrad": (-2100, -2400)}}
    detectors = {"SEARCH": ("double_cross",), "APPROACH": ("double_cross", "red_cylinder"),
                 "ADJUST": ("red_cylinder",), "LIFT": ("red_cylinder",)}
    search_detector = "double_cross"
    adjust_detector = "red_cylinder"
    check_detectors = ("red_cylinder",)
    held_look = False  # grasp check: look down at the object under the gripper (grasp.py)
    object_detectors = ("red_cylinder",)  # the double cross is the board, not the object
    grasp_alpha_mrad = 0
    keeps_sightings = False

    # --- SEARCH --------------------------------------------------------------------------------
    def found(self, t: Any, now: int, inp: Any, name: str, det: Any) -> bool:
        """The double cross's bearing e (and its spacing, for the blind approach)."""
        joints = t.arm_at(now - t.p.frame_latency_us)
        try:
            e = bearing_mrad(det, joints[5], t.cam)
        except (ValueError, TypeError):
            t.counters["bad_detections"] += 1
            return False
        if e is None:
            return False
        t.e_mrad, t.obj_seen_us = e, now
        t.e_dpx = d_pixel_px(det)
        return True

    def found_why(self, t: Any) -> str:
        return f"double cross seen at e = {t.e_mrad} mrad"

    # --- APPROACH: the fuzzy controller --------------------------------------------------------
    def enter_approach(self, t: Any, now: int, inp: Any) -> None:
        t.fuzzy = FuzzyApproach(FuzzyParams(**t.p.fuzzy))
        # the search's sighting is the first bearing to steer on if the next frames miss
        self.remember_bearing(t, inp, t.e_mrad, t.e_dpx)

    def approach(self, t: Any, now: int, inp: Any, dets: dict) -> None:
        """Steer with the fuzzy controller on the double cross's e (002 §2.1); ADJUST once the
        red cylinder is near, or placed near by the crosses."""
        rc = dets.get("red_cylinder")
        d_px = _spacing_px("red_cylinder", rc)
        if d_px is not None and t.see_object(now, inp, "red_cylinder", rc) and \
                d_px >= t.p.cylinder_near_px:
            t.go(now, "ADJUST", f"red cylinder seen, d_pixel = {d_px} px")
            return
        if t.obj is not None:  # the cylinder stands before the marker: do not run it over
            x, y = t.obj_platform(inp)
            dist = isqrt(x * x + y * y) // 16
            if dist <= t.p.grasp_r_mm + 150:
                t.go(now, "ADJUST", f"red cylinder estimated {dist} mm from the waist")
                return
        if not dets:
            return  # no new frame: keep the wheels as they are
        dc = dets.get("double_cross")
        yaw = t.arm_at(now - t.p.frame_latency_us)[5]  # the waist when the frame was taken
        try:
            e = bearing_mrad(dc, yaw, t.cam) if dc is not None else None
            if e is None and rc is not None:
                # the double cross out of reach but the cylinder in view (far, a few px wide):
                # steer on the cylinder's column, or the robot would stand still while the
                # cylinder's sightings keep LOST away
                u_c = registry.check("red_cylinder", rc).u_c_q4
                e = yaw + atan2_mrad(u_c - t.cam.u0_px * 16, t.cam.f_px * 16)
        except (ValueError, TypeError):
            t.counters["bad_detections"] += 1
            e = None
        if e is None and self.approach_blind(t, now, inp):
            return
        if e is None and now - t.obj_seen_us >= t.p.lost_timeout_us:
            t.go(now, "LOST", f"double cross not seen for {now - t.obj_seen_us} us")
            return
        dc_px = _spacing_px("double_cross", dc)
        if dc_px is not None and dc_px >= t.p.cross_near_px and \
                t.see_object(now, inp, "double_cross", dc):
            # near, the cylinder may be below the level look while the board is big in view:
            # its estimate from the crosses ends the approach (docs/cosim.md "Measured", T5)
            x, y = t.obj_platform(inp)
            dist = isqrt(x * x + y * y) // 16
            if dist <= t.p.grasp_r_mm + 150:
                t.go(now, "ADJUST", f"crosses {dc_px} px apart: red cylinder estimated "
                     f"{dist} mm from the waist")
                return
        cmd = t.fuzzy.step(now, e, None)
        if e is not None:
            t.obj_seen_us = now
            self.remember_bearing(t, inp, e, dc_px)
            self.track_marker(t, now, dc, e)
        t.wheels = (cmd.left_mm_s, cmd.right_mm_s)
        ec = None
        if e is not None and t.prev_e is not None and now > t.prev_e[0]:
            ec = (e - t.prev_e[1]) * 1_000_000 // (now - t.prev_e[0])
        t.prev_e = (now, e) if e is not None else None
        t.note(fuzzy={"e_mrad": e, "e_c_mrad_s": ec, "u_mrad": cmd.u_mrad,
                      "wheels_mmps": list(t.wheels)})

    def remember_bearing(self, t, inp, e: int, d_px: int | None) -> None:
        """The bearing to steer on blind should the next frames miss the marker, and how far:
        at most ``blind_approach_mm``, and ``blind_keep_mm`` short of the board's distance by
        the crosses' spacing. Near, a lost marker has left the view (the base turned, or it is
        below the look): driving on blind went past the object (docs/cosim.md "Measured", T6)."""
        t.blind = None
        if d_px is None or d_px <= 0:
            return
        board_mm = CROSS_SPACING_MM_Q4 * t.cam.f_px // (16 * d_px)
        reach = min(t.p.blind_approach_mm, board_mm - t.p.blind_keep_mm)
        if reach > 0:
            t.blind = (inp.heading_mrad - e, inp.x_mm, inp.y_mm, reach)

    def approach_blind(self, t, now: int, inp) -> bool:
        """No marker in this frame: steer on the bearing it was last seen at, by odometry, for
        up to the reach of :meth:`remember_bearing` and ``blind_approach_us``; True while
        doing so.

        Ours, not 002's (its fuzzy loop assumes the marker always in view): beyond ~2.5 m the
        crosses are ~10 px wide and the detector misses them in most frames, although the
        search (which holds still and confirms) did see them; standing still there ends in
        LOST -> SEARCH -> LOST until the object is given up (docs/cosim.md "Measured", T7)."""
        if t.blind is None:
            return False
        goal, x0, y0, reach = t.blind
        if (isqrt((inp.x_mm - x0) ** 2 + (inp.y_mm - y0) ** 2) >= reach
                or now - t.obj_seen_us >= t.p.blind_approach_us):
            return False
        e = wrap_mrad(inp.heading_mrad - goal)  # right positive, like the camera's e
        cmd = t.fuzzy.step(now, e, None)
        t.wheels = (cmd.left_mm_s, cmd.right_mm_s)
        t.set_arm(now, t.arm[2], t.arm[3], t.arm[4], max(-800, min(800, e)))
        t.prev_e = None
        t.note(fuzzy={"e_mrad": e, "e_c_mrad_s": None, "u_mrad": cmd.u_mrad,
                      "wheels_mmps": list(t.wheels), "blind": True})
        return True

    def track_marker(self, t, now: int, det, e: int) -> None:
        """Keep the marker in view: the waist faces it (theta5 = e) and d_alpha, the pitch of
        its pixel row off the optical centre, is shared by eq. (10) of 000 (host.posture)."""
        th5 = max(-800, min(800, e))
        # no double cross (steered on the red cylinder): the pitch is kept
        vm = det.vm_q4 if isinstance(det, DoubleCrossResult) else None
        d2 = d3 = d4 = 0
        if vm is not None:
            d_alpha = -atan2_mrad(vm - t.cam.v0_px * 16, t.cam.f_px * 16)
            cap = t.p.posture_step_mrad
            d_alpha = max(-cap, min(cap, d_alpha))
            d2, d3, d4 = distribute_alpha(d_alpha, *t.arm[2:5], t.posture_params(cap))
        t.set_arm(now, t.arm[2] + d2, t.arm[3] + d3, t.arm[4] + d4, th5)

    # --- ADJUST --------------------------------------------------------------------------------
    def adjust_done(self, t: Any, now: int, det: Any, dist_mm: int) -> bool:
        """d_pixel > T_d (002 §1: slowly on toward the cylinder until then). T_d of 002 says
        "in the workspace" for 002's camera placement; ours also needs the estimate within
        reach, else it creeps on (the close approach of adjust.py)."""
        d_px = _spacing_px("red_cylinder", det)
        if d_px is not None and d_px > t.p.t_d_px and \
                dist_mm <= t.p.grasp_r_mm + t.p.grasp_r_tol_mm:
            t.wheels = (0, 0)
            t.go(now, "ROUGH_GRASP", f"d_pixel = {d_px} px > T_d = {t.p.t_d_px}")
            return True
        return False

    def adjust_vmax_mmps(self, p: Any) -> int:
        return p.slow_mmps

    # --- the arm -------------------------------------------------------------------------------
    def look_height_mm(self, p: Any, top: bool) -> int:
        # the two rings sit at mid-height: keep them, not the top, in view
        return p.object_top_mm // 2 if top else p.grasp_height_mm

    def grasp_ik(self, geom: Any, target_q4: tuple[int, int, int]) -> Any:
        """Horizontal gripper (eq. (4) of 002) first, then tilted down by GRASP_ALPHAS_002."""
        first = None
        for a in GRASP_ALPHAS_002:
            res = kinematics.ik_pitch_mm_q4(geom, target_q4, a)
            if isinstance(res, kinematics.ArmPose):
                return res
            first = first or res
        return first

    def rough_target(self, t: Any, inp: Any) -> tuple[int, int, int]:
        """The pre-grasp point ``pregrasp_back_mm`` short of the axis at the grasp height."""
        return GRASP.object_target_q4(t, inp, t.p.grasp_height_mm, t.p.pregrasp_back_mm)

    def lowers_hover(self) -> bool:
        return False

    def enter_precise(self, t: Any, now: int, inp: Any) -> None:
        """Move in to the axis and lower. The pitch is chosen again (level first, eq. (4) of
        002): the pre-grasp point may only be reachable tilted, the axis often level."""
        pose = t.grasp_ik(GRASP.object_target_q4(t, inp, t.p.grasp_height_mm))
        if isinstance(pose, kinematics.Unreachable):
            t.fail(now, f"precise grasp IK: {pose.reason}")
            return
        t.apply_pose(now, pose)
        t.phase = "lower"


def _spacing_px(name: str, det: Any) -> int | None:
    """d_pixel in px of a result of detector ``name``; None for no result or one of another
    type (see_object counts those)."""
    if det is None or not isinstance(det, registry.row(name).result_type()):
        return None
    return d_pixel_px(det)


RULES = Method002()
