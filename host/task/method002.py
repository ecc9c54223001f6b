"""Paper 002's method: double cross, fuzzy approach, red cylinder, the level gripper.

SEARCH looks for the double cross (002 §2.1) and takes its bearing e, or, with no board in
view, for the red cylinder's colour ROI (002 §2.2 step 1: the cylinder is seen from every side,
the board's face only from in front); APPROACH steers with the fuzzy controller on e
(host.control.fuzzy: 35 rules, eq. (1) centroid, eq. (2) wheel law), the waist facing what it
steers on: the double cross when it is in view, as in 002, else the cylinder's column (its
rings near, its colour ROI far, the ROI's height giving a range); ADJUST "slows down and goes
straight with posture adjustment" (002 §1) in a look chosen so that the stop rule of 002 §4,
d_pixel > T_d, stops the base with the cylinder inside the level grasp's reach; ROUGH_GRASP
goes to the pre-grasp point with the gripper level by eq. (4) on the §4 position of the
cylinder (:meth:`Method002.object_position`), PRECISE_GRASP moves in to the axis and closes;
the grasp check of LIFT looks for the red cylinder still standing. Ours, not 002's: steering
on the cylinder without the board, the blind drive on toward the last bearing for a while
when a frame misses what was steered on, the end of the approach when the crosses, big in
view, place the cylinder near, and the back-off when the cylinder is then cut by the frame's
border (docs/task.md, "Close starts").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from mobigrasp.host import kinematics
from mobigrasp.host.control.fuzzy import FuzzyApproach, FuzzyParams
from mobigrasp.host.fixedpoint import atan2_mrad, isqrt
from mobigrasp.host.posture import distribute_alpha
from mobigrasp.host.ranging import locate_ring_pair
from mobigrasp.host.task.drive import turn_in_place, wrap_mrad
from mobigrasp.host.task.grasp import GRASP
from mobigrasp.host.task.method import PI, Method, MethodState, Param, SceneHints, mrad, q12
from mobigrasp.host.task.sense import (
    CAMERA_002,
    CROSS_SPACING_MM_Q4,
    bearing_mrad,
    d_pixel_px,
)
from mobigrasp.host.vision import double_cross, registry

if TYPE_CHECKING:
    from mobigrasp.host.task.machine import Task

GRASP_ALPHAS_002 = (0, -100, -200, -280)  # horizontal first; the world accepts |alpha| < 0.3
# the level grasp's reach (docs/task.md): scanned over these distances of the axis from the
# waist (mm, step), the ends of the window kept this far inside
LEVEL_SCAN_MM = (150, 350, 2)
LEVEL_MARGIN_MM = 2
WAIST_STEP_MRAD = 60  # APPROACH: the waist's turn toward e per frame (20 ms at 3 rad/s)
ADJUST_STALE_BACK_MM = 40  # ADJUST: the backstop this much nearer on an older estimate
SEARCH_COVER_002_MM = 2500  # SEARCH gives up once its wander has covered this disc
# APPROACH: a cylinder cut by the frame's border (its colour ROI touching it, its rings not
# measured) when the estimate would start ADJUST within BACK_OFF_WITHIN_MM beyond grasp_r_mm
# (farther, ADJUST's look pitched down sees it whole): back straight off BACK_OFF_002_MM (inside
# the 0.35 m the generator keeps clear behind a start: footprint radius 170 mm) and look again,
# at most BACK_OFFS_002 times in a run (docs/task.md, "Close starts")
BACK_OFF_WITHIN_MM = 60
BACK_OFF_002_MM = 150
BACK_OFFS_002 = 2
# APPROACH: the board alone. The cylinder stands 0.15 m before the board's face, the one the
# crosses are printed on, and its colour ROI is found from any side at 0.4-3 m: a frame that
# shows the crosses BOARD_ALONE_MM away by their spacing (an oblique board reads farther than
# it is) shows the cylinder too. BOARD_ALONE_FRAMES such frames without red, before any frame
# of the approach showed red, end the run: no graspable object (docs/task.md)
BOARD_ALONE_MM = (600, 2000)
BOARD_ALONE_FRAMES = 15
# the grasp check's look (docs/task.md): the fingertip, and a held cylinder with it, brought to
# (reach mm ahead of the waist, height mm above the ground) with the camera pitched down (mrad),
# first reachable wins: a cylinder left standing is then ~150 mm further out and below the view
HELD_VIEWS_002 = ((100, 160, 800), (80, 160, 900), (90, 160, 850), (110, 155, 800))


@dataclass
class State002(MethodState):
    """What 002 keeps between steps (the task's ``ms``)."""

    fuzzy: FuzzyApproach | None = None  # the fuzzy approach of APPROACH (002 §2.1)
    e_mrad: int = 0  # the bearing e the approach steers on
    prev_e: tuple[int, int] | None = None  # (t_us, e) of the last frame that gave e
    # the blind drive on toward the marker: (its odometry bearing, x_mm, y_mm, reach_mm)
    blind: tuple[int, int, int, int] | None = None
    e_dpx: int | None = None  # d_pixel of the search's sighting
    steer_on: str = ""  # what the search found and the approach steers on
    e_range_mm: int | None = None  # range of the search's red ROI (its height), if known
    cut: bool = False  # the last frame showed the cylinder cut by the border (no rings)
    back_offs: int = 0  # back-offs made in the run
    # the back-off under way: (x_mm, y_mm where it started, t_us it ended or None)
    back_off: tuple[int, int, int | None] | None = None
    red_seen: bool = False  # a frame of APPROACH showed the red cylinder (rings or ROI)
    alone_frames: int = 0  # ... before it, frames of the crosses in BOARD_ALONE_MM, no red
    look_back: bool = False  # the sonar guard drove out of R_r: turn back to the estimate


class Method002(Method):
    """002: the hooks of the machine's states (host/task/method.py)."""

    name = "002"
    State = State002
    # 002 §5's values and their ranges
    paper_params = {
        "T_h": Param(int, 30, 1, 255, "grey levels, threshold"),
        "n": Param(int, 10, 1, 100, "frames"),
        "e_th": Param(float, 1.43, 0.01, PI, "rad, error threshold"),
        "e_cth": Param(float, 5.0, 0.01, 50.0, "rad/s, error-rate threshold"),
        "u_th": Param(float, 1.0, 0.01, 10.0, "rad/s, output threshold"),
        "V_avg": Param(float, 0.15, 0.01, 1.0, "m/s, mean approach speed"),
        "k_u": Param(float, 1.0, 0.01, 7.0, "output gain"),
        "D": Param(float, 0.0145, 0.001, 0.1, "m, spacing of the rings"),
        "T_d": Param(float, 45.0, 1.0, 320.0, "px, distance threshold"),
    }
    # T_h (the double-cross detector's own threshold), n (frames) and D (the ring spacing of
    # the cylinder as made)
    not_used_params = ("T_h", "n", "D")
    paper_to_task = {
        "e_th": ("fuzzy", "e_th_mrad", mrad), "e_cth": ("fuzzy", "e_cth_mrad_s", mrad),
        "u_th": ("fuzzy", "u_th_mrad", mrad),
        "V_avg": ("fuzzy", "v_avg_mm_s", mrad),  # m/s -> mm/s
        "k_u": ("fuzzy", "k_uc_q12", q12),
        "T_d": ("fuzzy", "t_d_px", lambda v: int(round(v)))}
    scene = SceneHints("red-cylinder", 120.0, guide_board=True, moving_target=True)
    robot = "002"
    link_lengths_mm = (97.0, 89.0, 95.5)
    camera = CAMERA_002
    # the level gripper of 002 (eq. (4)) with theta2 <= 0 reaches the grasp point 50 mm above
    # the low shoulder only 230..275 mm ahead of the waist (pitch 0..-0.28 rad): stop the base
    # 255 +- 15 mm short and come in from 40 mm short of the axis
    param_defaults = {"h_shoulder_mm": 50, "object_top_mm": 120, "grasp_height_mm": 100,
                      "grasp_r_mm": 255, "grasp_r_tol_mm": 15, "pregrasp_back_mm": 40,
                      # the double cross stands upright, far: the paper's first cycle, then the
                      # level look (f = 350 px: 0.66 rad vertical field)
                      "search": {"dense_cycles": 1, "coarse_theta2_mrad": (-2100, -2400),
                                 "cover_mm": SEARCH_COVER_002_MM},
                      # ADJUST's look (shoulder 2.12 rad, elbow -2.19 rad, theta2 pitching the
                      # camera at the rings): the camera ~130 mm ahead of the waist and ~100 mm
                      # up, so that d_pixel passes T_d = 45 px with the cylinder's axis ~252 mm
                      # ahead of the waist, inside the level grasp's reach (docs/task.md)
                      "adjust_theta3_mrad": -2190, "adjust_theta4_mrad": 2120,
                      # eq. (10)'s margins as room to the joint limits: the printed theta2m =
                      # theta2 leaves no room to pitch down from theta2 = 0 (host/posture.py)
                      "posture": {"margin_mode": "limits"}}
    detectors = {"SEARCH": ("double_cross", "red_roi"),
                 "APPROACH": ("double_cross", "red_cylinder", "red_roi"),
                 "ADJUST": ("red_cylinder",), "LIFT": ("red_cylinder", "held_fill")}
    search_detector = "double_cross"
    adjust_detector = "red_cylinder"
    check_detectors = ("red_cylinder",)
    held_colour = "red_paint"
    object_detectors = ("red_cylinder",)  # the double cross is the board, not the object
    grasp_alpha_mrad = 0
    keeps_sightings = False

    # --- SEARCH --------------------------------------------------------------------------------
    def search_sighting(self, dets: dict) -> tuple[str, Any]:
        """The double cross when this frame shows it (002 §2.1), else the red cylinder's colour
        ROI (002 §2.2 step 1): the cylinder is seen from every side, the board's face only
        from in front of it."""
        if dets.get("double_cross") is not None:
            return "double_cross", dets["double_cross"]
        return "red_roi", dets.get("red_roi")

    def found(self, t: Task, now: int, inp: Any, name: str, det: Any) -> bool:
        """The bearing e of the double cross (and its spacing, for the blind approach) or of
        the red ROI's column (and its range from its height, when the box is whole)."""
        joints = t.arm_at(now - t.p.frame_latency_us)
        try:
            if name == "double_cross":
                e = bearing_mrad(det, joints[5], t.cam)
                dist = None
            else:
                e = _column_bearing(t, registry.check("red_roi", det).u_c_q4, joints[5])
                dist = _roi_range_mm(t, det)
        except (ValueError, TypeError):
            t.counters["bad_detections"] += 1
            return False
        if e is None:
            return False
        t.ms.e_mrad, t.obj_seen_us = e, now
        t.ms.steer_on = "double cross" if name == "double_cross" else "red cylinder"
        t.ms.e_dpx = d_pixel_px(det) if name == "double_cross" else None
        t.ms.e_range_mm = dist
        return True

    def search_gives_up(self, t: Task) -> str | None:
        """Nothing seen in a look around (the red ROI is found from any side out to 3 m and
        beyond, docs/task.md) and a wander that covered the disc of ``SEARCH_COVER_002_MM``
        (host.coverage): no graspable object."""
        if t.graspable_seen or not t.search.covered:
            return None
        return (f"the search saw neither the double cross nor the red cylinder in "
                f"{t.search.cycle} cycles and {t.search.wanders} wander legs")

    def found_why(self, t: Task) -> str:
        if t.ms.steer_on == "double cross":
            return f"double cross seen at e = {t.ms.e_mrad} mrad"
        return f"red cylinder's colour ROI seen at e = {t.ms.e_mrad} mrad (no double cross in view)"

    # --- APPROACH: the fuzzy controller --------------------------------------------------------
    def enter_approach(self, t: Task, now: int, inp: Any) -> None:
        t.ms.fuzzy = FuzzyApproach(FuzzyParams(**t.p.fuzzy))
        # the search's sighting is the first bearing to steer on if the next frames miss
        self.remember_bearing(t, inp, t.ms.e_mrad, _board_range_mm(t, t.ms.e_dpx)
                              if t.ms.e_dpx else t.ms.e_range_mm)

    def approach(self, t: Task, now: int, inp: Any, dets: dict) -> None:
        """Steer with the fuzzy controller on e (002 §2.1): the double cross's when it is in
        view, as 002 does, else the red cylinder's column (its rings, or its colour ROI far
        away); ADJUST once the cylinder is near, or placed near by the crosses."""
        rc = dets.get("red_cylinder")
        roi = dets.get("red_roi")
        if t.ms.back_off is not None and self.backing_off(t, now, inp, dets):
            return
        if dets:
            t.ms.cut = rc is None and _roi_cut(t, roi)
        d_px = _spacing_px("red_cylinder", rc)
        if d_px is not None and t.see_object(now, inp, "red_cylinder", rc) and \
                d_px >= t.p.cylinder_near_px:
            t.go(now, "ADJUST", f"red cylinder seen, d_pixel = {d_px} px")
            return
        if d_px is None and _roi_range_mm(t, roi) is not None:
            t.see_object(now, inp, "red_roi", roi)  # far: the range from the ROI's height
        if t.obj is not None:  # the cylinder stands before the marker: do not run it over
            x, y = t.obj_platform(inp)
            dist = isqrt(x * x + y * y) // 16
            if dist <= t.p.grasp_r_mm + 150:
                if not self.backs_off(t, inp, dist):
                    t.go(now, "ADJUST", f"red cylinder estimated {dist} mm from the waist")
                return
        if not dets:
            return  # no new frame: keep the wheels as they are
        if self.board_alone(t, now, dets):
            return
        dc = dets.get("double_cross")
        yaw = t.arm_at(now - t.p.frame_latency_us)[5]  # the waist when the frame was taken
        e = vm = cue_mm = None  # bearing, image row to keep centred, range of the cue
        cue = None
        try:
            if dc is not None:
                e, cue = bearing_mrad(dc, yaw, t.cam), "double cross"
                vm = registry.check("double_cross", dc).vm_q4
                dc_spacing = _spacing_px("double_cross", dc)
                cue_mm = _board_range_mm(t, dc_spacing) if dc_spacing else None
            elif d_px is not None or roi is not None:
                # the double cross out of view (turned away, or out of reach): steer on the
                # cylinder's column, its rings near, its colour ROI far (ours: 002 steers on
                # the board alone)
                name, cyl = ("red_cylinder", rc) if d_px is not None else ("red_roi", roi)
                cyl = registry.check(name, cyl)
                e, vm, cue = _column_bearing(t, cyl.u_c_q4, yaw), cyl.v_c_q4, name
                cue_mm = _roi_range_mm(t, roi) if name == "red_roi" else None
        except (ValueError, TypeError):
            t.counters["bad_detections"] += 1
            e = None
        if e is None and self.looks_back(t, now, inp):
            return
        if e is None and self.approach_blind(t, now, inp):
            return
        if e is None and now - t.obj_seen_us >= t.p.lost_timeout_us:
            t.go(now, "LOST", f"neither the double cross nor the red cylinder seen for "
                 f"{now - t.obj_seen_us} us")
            return
        dc_px = _spacing_px("double_cross", dc)
        if dc_px is not None and dc_px >= t.p.cross_near_px and double_cross.level_pair(dc) \
                and t.see_object(now, inp, "double_cross", dc):
            # near, the cylinder may be below the level look while the board is big in view:
            # its estimate from the crosses ends the approach (docs/cosim.md "Measured", T5);
            # a pair far from level is not the board's crosses (docs/task.md)
            x, y = t.obj_platform(inp)
            dist = isqrt(x * x + y * y) // 16
            if dist <= t.p.grasp_r_mm + 150:
                if not self.backs_off(t, inp, dist):
                    t.go(now, "ADJUST", f"crosses {dc_px} px apart: red cylinder estimated "
                         f"{dist} mm from the waist")
                return
        cmd = t.ms.fuzzy.step(now, e, None)
        if e is not None:
            t.obj_seen_us, t.ms.look_back = now, False
            self.remember_bearing(t, inp, e, cue_mm)
            self.track_marker(t, now, vm, e)
        t.wheels = (cmd.left_mm_s, cmd.right_mm_s)
        ec = None
        if e is not None and t.ms.prev_e is not None and now > t.ms.prev_e[0]:
            ec = (e - t.ms.prev_e[1]) * 1_000_000 // (now - t.ms.prev_e[0])
        t.ms.prev_e = (now, e) if e is not None else None
        t.note(fuzzy={"e_mrad": e, "e_c_mrad_s": ec, "u_mrad": cmd.u_mrad,
                      "wheels_mmps": list(t.wheels), "steer_on": cue})

    def board_alone(self, t: Task, now: int, dets: dict) -> bool:
        """The board without its cylinder: BOARD_ALONE_FRAMES frames showing the crosses within
        BOARD_ALONE_MM by their spacing and no red (neither rings nor colour ROI), before the
        red cylinder was seen in any frame of the approach. The cylinder stands before the
        crosses' face and its ROI is found from every side out to 3 m, so such frames would
        show it: FAILED "no graspable object found" (True), rather than driving on into the
        board and searching until the time limit."""
        if t.ms.red_seen or t.graspable_seen:
            return False
        if _is_result("red_cylinder", dets.get("red_cylinder")) or \
                _is_result("red_roi", dets.get("red_roi")):
            t.ms.red_seen = True
            return False
        d_px = _spacing_px("double_cross", dets.get("double_cross"))
        if not d_px or not BOARD_ALONE_MM[0] <= _board_range_mm(t, d_px) <= BOARD_ALONE_MM[1]:
            return False
        t.ms.alone_frames += 1
        if t.ms.alone_frames < BOARD_ALONE_FRAMES:
            return False
        t.fail(now, f"no graspable object found: the double cross seen in {t.ms.alone_frames} "
               f"frames {BOARD_ALONE_MM[0]}-{BOARD_ALONE_MM[1]} mm away, no red cylinder "
               f"before it")
        return True

    def backs_off(self, t: Task, inp, dist_mm: int) -> bool:
        """The estimate would start ADJUST ``dist_mm`` from the waist, within
        BACK_OFF_WITHIN_MM beyond the grasp's reach, while the last frame showed the cylinder
        cut by the frame's border, its rings not measured: too close to be seen whole (or off
        the estimate's bearing), ADJUST would close in on an estimate the rings never confirm.
        Back straight off BACK_OFF_002_MM instead (at most BACK_OFFS_002 times) and look
        again; True when it does."""
        if not t.ms.cut or t.ms.back_offs >= BACK_OFFS_002 \
                or dist_mm > t.p.grasp_r_mm + BACK_OFF_WITHIN_MM:
            return False
        t.ms.back_offs += 1
        t.ms.back_off = (inp.x_mm, inp.y_mm, None)
        t.wheels = (-t.p.slow_mmps, -t.p.slow_mmps)
        t.note(back_off={"dist_mm": dist_mm, "n": t.ms.back_offs})
        return True

    def backing_off(self, t: Task, now: int, inp, dets: dict) -> bool:
        """The back-off under way: straight back at ``slow_mmps`` until BACK_OFF_002_MM from
        where it started, then still until a frame taken after it ended has come; True until
        then (that frame is the approach's again, LOST counted from it)."""
        x0, y0, ended_us = t.ms.back_off
        if ended_us is None:
            dx, dy = inp.x_mm - x0, inp.y_mm - y0
            if dx * dx + dy * dy < BACK_OFF_002_MM * BACK_OFF_002_MM:
                t.wheels = (-t.p.slow_mmps, -t.p.slow_mmps)
                return True
            ended_us = now
            t.ms.back_off = (x0, y0, now)
        t.wheels = (0, 0)
        if not dets or now - t.p.frame_latency_us < ended_us:
            return True
        t.ms.back_off = None
        t.obj_seen_us = now
        return False

    def remember_bearing(self, t: Task, inp, e: int, cue_mm: int | None) -> None:
        """The bearing to steer on blind should the next frames miss the board or the
        cylinder, and how far: at most ``blind_approach_mm``, and ``blind_keep_mm`` short of
        the range of what was seen (the board by its crosses' spacing, the cylinder by its
        ROI's height). Near, a lost marker has left the view (the base turned, or it is below
        the look): driving on blind went past the object (docs/cosim.md "Measured", T6)."""
        t.ms.blind = None
        if cue_mm is None or cue_mm <= 0:
            return
        reach = min(t.p.blind_approach_mm, cue_mm - t.p.blind_keep_mm)
        if reach > 0:
            t.ms.blind = (inp.heading_mrad - e, inp.x_mm, inp.y_mm, reach)

    def looks_back(self, t: Task, now: int, inp) -> bool:
        """No cue in this frame while the sonar guard drives the base out of R_r, or after it
        until the base faces the cylinder's estimate again (turning in place, by odometry):
        True meanwhile, the lost timeout counted from then. The drive out turns the base away
        on purpose; counted lost, the approach went LOST and searched again from there
        (docs/task.md, "002: the false pairs of crosses")."""
        if t.guard_out is not None:
            t.ms.look_back = t.obj is not None
            t.obj_seen_us = now
            return True
        if not t.ms.look_back:
            return False
        x, y = t.obj_platform(inp)
        bearing = atan2_mrad(x, y + t.p.mount_forward_mm * 16)  # seen from the axle
        if abs(bearing) <= t.p.bearing_tol_mrad:
            t.ms.look_back = False
            return False
        t.wheels = turn_in_place(-1 if bearing > 0 else 1, t.p.turn_wheel_mmps)
        t.obj_seen_us = now
        t.note(look_back={"bearing_mrad": bearing})
        return True

    def approach_blind(self, t: Task, now: int, inp) -> bool:
        """No marker in this frame: steer on the bearing it was last seen at, by odometry, for
        up to the reach of :meth:`remember_bearing` and ``blind_approach_us``; True while
        doing so.

        Ours, not 002's (its fuzzy loop assumes the marker always in view): beyond ~2.5 m the
        crosses are ~10 px wide and the detector misses them in most frames, although the
        search (which holds still and confirms) did see them; standing still there ends in
        LOST -> SEARCH -> LOST until the object is given up (docs/cosim.md "Measured", T7)."""
        if t.ms.blind is None:
            return False
        goal, x0, y0, reach = t.ms.blind
        if (isqrt((inp.x_mm - x0) ** 2 + (inp.y_mm - y0) ** 2) >= reach
                or now - t.obj_seen_us >= t.p.blind_approach_us):
            return False
        e = wrap_mrad(inp.heading_mrad - goal)  # right positive, like the camera's e
        cmd = t.ms.fuzzy.step(now, e, None)
        t.wheels = (cmd.left_mm_s, cmd.right_mm_s)
        t.set_arm(now, t.arm[2], t.arm[3], t.arm[4], max(-800, min(800, e)))
        t.ms.prev_e = None
        t.note(fuzzy={"e_mrad": e, "e_c_mrad_s": None, "u_mrad": cmd.u_mrad,
                      "wheels_mmps": list(t.wheels), "blind": True})
        return True

    def track_marker(self, t: Task, now: int, vm_q4: int | None, e: int) -> None:
        """Keep what is steered on in view: the waist faces it (theta5 = e) and d_alpha, the
        pitch of its pixel row ``vm_q4`` off the optical centre, is shared by eq. (10) of 000
        (host.posture); no row: the pitch is kept."""
        # toward e by at most WAIST_STEP_MRAD a frame: a bigger jump is still under way when
        # the next frame is taken, whose bearing then reads the waist wrong (the yaw of a
        # frame is the target the waist was sent, host/task/machine.py arm_at)
        step = max(-WAIST_STEP_MRAD, min(WAIST_STEP_MRAD, e - t.arm[5]))
        th5 = max(-800, min(800, t.arm[5] + step))
        d2 = d3 = d4 = 0
        if vm_q4 is not None:
            d_alpha = -atan2_mrad(vm_q4 - t.cam.v0_px * 16, t.cam.f_px * 16)
            cap = t.p.posture_step_mrad
            d_alpha = max(-cap, min(cap, d_alpha))
            d2, d3, d4 = distribute_alpha(d_alpha, *t.arm[2:5], t.posture_params(cap))
        t.set_arm(now, t.arm[2] + d2, t.arm[3] + d3, t.arm[4] + d4, th5)

    # --- ADJUST --------------------------------------------------------------------------------
    def adjust_done(self, t: Task, now: int, det: Any, dist_mm: int) -> bool:
        """The stop rule of 002 §4: d_pixel > T_d, "the object is in the workspace". ADJUST's
        look (``adjust_theta3_mrad``, ``adjust_theta4_mrad``) puts that ring spacing at the
        level grasp's reach; a frame taken before the arm settled in it does not count."""
        d_q4 = _spacing_q4(det)
        if d_q4 is None or now - t.p.frame_latency_us < t.trust_from_us:
            return False
        if d_q4 > 16 * t.p.t_d_px:
            t.wheels = (0, 0)
            t.go(now, "ROUGH_GRASP", f"stop rule d_pixel > T_d: d_pixel = {d_q4 / 16:.1f} px > "
                 f"T_d = {t.p.t_d_px} px, red cylinder estimated {dist_mm} mm from the waist")
            return True
        return False

    def adjust_goal_mm(self, t: Task) -> tuple[int, int]:
        """The estimate's stop only backs the stop rule up (rings not measured): at the near
        end of the level grasp's reach, past where d_pixel passes T_d; and only on an estimate
        of this ADJUST's look (one from elsewhere, e.g. the grasp check's steep look, may be
        15 mm short): until then the goal is ``ADJUST_STALE_BACK_MM`` nearer."""
        goal = t.p.grasp_r_mm - 25
        if t.obj_seen_us < t.trust_from_us + t.p.frame_latency_us:
            goal -= ADJUST_STALE_BACK_MM
        return goal, 5

    def adjust_vmax_mmps(self, p: Any) -> int:
        return p.slow_mmps

    def grasp_reach_mm(self, t: Task) -> tuple[int, int] | None:
        """The distances of the axis from the waist where the gripper holds it level at the
        grasp height within the joint limits (eq. (4) of 002: theta1 + theta2 + theta3 = 0),
        as centre and half width: on this arm a window ~8 mm wide ~271 mm out, beyond the
        stop of d_pixel > T_d (~252 mm), so the base backs off to it before the grasp."""
        z = (t.p.grasp_height_mm - t.p.h_shoulder_mm) * 16
        lo_mm, hi_mm, step = LEVEL_SCAN_MM
        level = [r for r in range(lo_mm, hi_mm + 1, step) if isinstance(
            kinematics.ik_pitch_mm_q4(t.geom, (0, r * 16, z), 0), kinematics.ArmPose)]
        if not level:
            return None
        lo, hi = level[0], level[-1]
        return (lo + hi) // 2, max(1, (hi - lo) // 2 - LEVEL_MARGIN_MM)

    def object_position(self, t: Task, name: str, det: Any, joints: tuple[int, ...]) -> Any:
        """The red cylinder's axis point between its rings by 002 §4: D_OC = D f / d_pixel along
        the ray of (u_c, v_c) whose vertical and horizontal angles are theta_v = alpha +
        atan((v0 - v_c)/f) and theta_h = theta5 + atan((u_c - u0)/f), in the exact pinhole
        form of host.ranging.locate_ring_pair (the rings' segment seen pitched, then the
        radius from the red width to the axis), added to the camera point of eq. (3) (X_OR =
        X_OC + X_CR ...). Other detectors, or a rolled wrist: the pinhole sighting."""
        if name != "red_cylinder" or joints[1] != 0:
            return super().object_position(t, name, det, joints)
        det = registry.check("red_cylinder", det)
        if det.d_pixel_q4 <= 0:
            return None
        fix = locate_ring_pair(det.d_pixel_q4, det.u_c_q4, det.v_c_q4, det.width_q4,
                               joints[2] + joints[3] + joints[4], joints[5], t.cam.f_px,
                               t.cam.u0_px, t.cam.v0_px)
        cx, cy, cz = kinematics.fk_mm_q4(t.geom, *joints[2:6])
        return cx + 16 * fix.x_mm, cy + 16 * fix.y_mm, cz + 16 * fix.z_mm

    def object_cue_seen(self, t: Task) -> bool:
        """The red cylinder's colour ROI or rings in a frame of APPROACH (``red_seen``)."""
        return t.ms.red_seen

    def failure_reason(self, t: Task, reason: str) -> str:
        """A run that never saw the red cylinder (a board alone) says so whatever ended it."""
        if t.graspable_seen or reason.startswith("no graspable object found"):
            return reason
        return f"no graspable object found (red_cylinder never seen): {reason}"

    # --- the grasp check --------------------------------------------------------------------
    def held_view_pose(self, t: Task) -> Any:
        """The look of the grasp check (docs/task.md): the fingertip, and a held cylinder
        with it, brought in along its bearing to one of ``HELD_VIEWS_002`` with the camera
        pitched down; a cylinder left standing stays at its place, ~150 mm further out.
        None when none is reachable."""
        x, y, _ = t.gripper_point_q4()
        rho = isqrt(x * x + y * y)
        if rho <= 0:
            return None
        for r_mm, z_mm, pitch in HELD_VIEWS_002:
            target = (x * r_mm * 16 // rho, y * r_mm * 16 // rho, (z_mm - t.p.h_shoulder_mm) * 16)
            pose = kinematics.ik_pitch_mm_q4(t.geom, target, -pitch)
            if isinstance(pose, kinematics.ArmPose):
                return pose
        return None

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

    def rough_target(self, t: Task, inp: Any) -> tuple[int, int, int]:
        """The pre-grasp point ``pregrasp_back_mm`` short of the axis at the grasp height."""
        return GRASP.object_target_q4(t, inp, t.p.grasp_height_mm, t.p.pregrasp_back_mm)

    def lowers_hover(self) -> bool:
        return False

    def enter_precise(self, t: Task, now: int, inp: Any) -> None:
        """Move in to the axis and lower. The pitch is chosen again (level first, eq. (4) of
        002): the pre-grasp point may only be reachable tilted, the axis often level."""
        pose = t.grasp_ik(GRASP.object_target_q4(t, inp, t.p.grasp_height_mm))
        if isinstance(pose, kinematics.Unreachable):
            t.fail(now, f"precise grasp IK: {pose.reason}")
            return
        t.apply_pose(now, pose)
        t.phase = "lower"


def _column_bearing(t: Task, u_q4: int, theta5_mrad: int) -> int:
    """Bearing from the platform heading (right positive) of image column ``u_q4`` seen with
    the waist at ``theta5_mrad`` (level roll: the pitch does not turn the image)."""
    return theta5_mrad + atan2_mrad(u_q4 - t.cam.u0_px * 16, t.cam.f_px * 16)


def _board_range_mm(t: Task, d_px: int) -> int:
    """The board's distance by its crosses' spacing (pinhole)."""
    return CROSS_SPACING_MM_Q4 * t.cam.f_px // (16 * d_px)


def _roi_range_mm(t: Task, roi: Any) -> int | None:
    """The red ROI's range by its height (host/vision/red_cylinder.py ``roi_sighting``), or
    None (no ROI, or its box cut by the frame)."""
    if roi is None or not isinstance(roi, registry.row("red_roi").result_type()):
        return None
    seen = registry.row("red_roi").sighting_fn()(roi, t.cam.f_px)
    return None if seen is None else seen[2] // 16


def _roi_cut(t: Task, roi: Any) -> bool:
    """The red ROI's box touches the frame's border (the frame 2 u0 x 2 v0 px): the cylinder
    is not wholly in view. No ROI, or a result of another type: False."""
    if roi is None or not isinstance(roi, registry.row("red_roi").result_type()):
        return False
    x, y, w, h = roi.roi
    return x <= 0 or y <= 0 or x + w >= 2 * t.cam.u0_px or y + h >= 2 * t.cam.v0_px


def _is_result(name: str, det: Any) -> bool:
    """``det`` is a result of detector ``name`` (not none, not another type)."""
    return det is not None and isinstance(det, registry.row(name).result_type())


def _spacing_q4(det: Any) -> int | None:
    """d_pixel in Q4 px of a red cylinder result; None for none or another type."""
    return det.d_pixel_q4 if _is_result("red_cylinder", det) else None


def _spacing_px(name: str, det: Any) -> int | None:
    """d_pixel in px of a result of detector ``name``; None for no result or one of another
    type (see_object counts those)."""
    return d_pixel_px(det) if _is_result(name, det) else None


RULES = Method002()
