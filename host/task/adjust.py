"""ADJUST: the close approach on the object estimate, with the posture adjustment.

000 / 001: the vision-based approaching adjustment of 000 §III.B with the dual "+" (the radial
symbol when the "+" are out of the detector's range); 002 "slows down and goes straight with
posture adjustment" (002 §1) on the red cylinder until its ring spacing says the object is in
the workspace (``Method.adjust_done``). The close approach is host/task/drive.py's
:func:`close_in`; LOST when the object has not been seen for ``lost_timeout_us`` and odometry
alone would not finish. Each handler takes the task ``t`` first.
"""

from __future__ import annotations

from mobigrasp.host.fixedpoint import isqrt
from mobigrasp.host.task.drive import close_in


class AdjustState:
    """Entry action and step of ADJUST."""

    def enter_ADJUST(self, t, now: int, inp) -> None:
        """From the posture the arm enters with, the joints moved by eq. (10) of 000 alone
        (``Method.adjust_keeps_posture``); else the close-look posture (ours): shoulder up,
        elbow bent, so that theta2 alone (000's k_theta2 = 1) can pitch the camera down to the
        object at arm's length; alpha is kept."""
        if not t.rules.adjust_keeps_posture:
            th3, th4 = t.p.adjust_theta3_mrad, t.p.adjust_theta4_mrad
            alpha = t.arm[2] + t.arm[3] + t.arm[4]
            t.set_arm(now, alpha - th3 - th4, th3, th4, t.arm[5])
            t.trust_from_us = t.move_done_us
        t.obj_seen_us = max(t.obj_seen_us, t.move_done_us)  # LOST counts from then

    def do_ADJUST(self, t, now: int, inp, dets: dict) -> None:
        name = t.rules.adjust_detector
        det = dets.get(name)
        if det is not None:
            t.see_object(now, inp, name, det)
        elif dets.get("radial_symbol") is not None:  # the dual "+" out of its range: the rings
            t.see_object(now, inp, "radial_symbol", dets["radial_symbol"])
        x, y = t.obj_platform(inp)
        if det is not None and t.rules.adjust_done(t, now, det, isqrt(x * x + y * y) // 16):
            return
        # the estimate stops the close approach at grasp_r_mm (clear of the footprint)
        vmax = t.rules.adjust_vmax_mmps(t.p)
        goal_mm, tol_mm = t.rules.adjust_goal_mm(t)
        wheels, done, d = close_in((x, y), goal_mm, tol_mm, t.p.bearing_tol_mrad, vmax)
        t.note(adjust=d)
        unseen = now - t.obj_seen_us
        if unseen >= t.p.lost_timeout_us and abs(d["err_mm"]) > t.p.blind_finish_mm:
            t.wheels = (0, 0)
            t.lost_in = "ADJUST"  # the search that follows may differ (Method.lost_search)
            t.go(now, "LOST", f"{name} not seen for {unseen} us, {d['dist_mm']} mm away")
            return
        t.look_at_object(inp)
        t.wheels = wheels
        if done:
            t.go(now, "ROUGH_GRASP", f"object {d['dist_mm']} mm ahead of the waist, "
                 f"bearing {d['bearing_mrad']} mrad")


ADJUST = AdjustState()
