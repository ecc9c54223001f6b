"""Single "+" spoke of paper 000 (§III.A, Fig. 3) for the precise grasp: slope k_l and width w_l.

When only one "+" is in view (camera straight above the object, 0.09-0.18 m over the top), the
recognition template of Fig. 3 scans columns across the spoke (points "x") and takes the
middle of the dark run in each as a central point "o" (u_s, v_s), s = 1..k_s (k_s = 5, §IV).
The slope is ``k_l = mean(k_b)`` with ``k_b`` the slope between central points b and b+1, and
w_l is the spoke's width in the image. The precise grasp goes down when ``k_T = 0`` and
``w_T in [w_min, w_max] = [20, 40]`` px (§III.C, §IV): :func:`grasp_ready`.

Our template: the "+" nearest the image centre (candidates as in host.vision.dual_plus); of
its four spokes the two nearest the image x axis (left and right arms), k_s = 5 columns on each
at 0.50-0.62 of the arm's reach (clear of the neighbouring spoke and of the slanted tip); in each
column the dark run nearest the line predicted from the arm's direction, with sub-pixel ends
(mid-level crossings); a point whose run is not within 0.85-1.3 of the median (the column also
cut the next spoke, or the tip) is dropped; a second pass follows the line the first found.
k_l is the least-squares slope through the central points of both arms (``_template`` says why
not the plain mean of the k_b) in Q12 (dv/du; image v grows downwards), also as an angle in
mrad; the run length is the vertical width and ``w_l = run cos(atan k_l)``. Integer only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mobigrasp.host import fixedpoint as fp
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.vision import dark_blobs as db
from mobigrasp.host.vision.dual_plus import Plus, plus_candidates

K_S = 5  # 000 §IV: central points per spoke
W_MIN_PX, W_MAX_PX = 20, 40  # 000 §IV
_COLUMN_OPS = db.EDGE_OPS.scaled(2) + OpCounts(pixels_read=20, alu=30, branches=20, divs=1)
_CALL_OPS = OpCounts(alu=200)  # the call and its candidate scratch set-up (hostc/spoke.c)
SECOND_PASS_Q12 = 722  # tan(10 degrees) in Q12
MAX_ANGLE_MRAD = 524  # arms within 30 degrees of image x (the roll joint turns the wrist first)


@dataclass(frozen=True)
class Spoke:
    """Spoke measured on the "+" nearest the image centre (pixels in Q4, v downwards)."""

    u_c_q4: int  # centre of the "+"
    v_c_q4: int
    points_q4: tuple[tuple[int, int], ...]  # central points "o", left arm then right arm
    slope_q12: int  # k_l = dv/du in Q12 (least squares, see _template)
    angle_mrad: int  # atan(k_l)
    width_q4: int  # w_l, across the spoke


def grasp_ready(s: Spoke, w_min_px: int = W_MIN_PX, w_max_px: int = W_MAX_PX,
                tol_mrad: int = 17) -> bool:
    """000 §III.C: grasp downwards if k_T = 0 (within ``tol_mrad``) and w_T in [w_min, w_max]."""
    return abs(s.angle_mrad) <= tol_mrad and 16 * w_min_px <= s.width_q4 <= 16 * w_max_px


def _arm_direction(sel: np.ndarray, x: int, y: int, uc_q4: int, vc_q4: int, side: int
                   ) -> tuple[int, int, int] | None:
    """(du, dv, reach) of one side arm: centroid direction (Q4 px) of the "+" pixels in the
    45-degree cone on that side beyond half the reach, and the reach (px) of the cone."""
    ys, xs = db.nonzero_yx(sel)
    du = (16 * (xs + x) - uc_q4) * side
    dv = 16 * (ys + y) - vc_q4
    cone = du > np.abs(dv)
    if not cone.any():
        return None
    reach = int(du[cone].max()) // 16
    far = cone & (2 * du > 16 * reach)
    if not far.any():
        return None
    return int(du[far].sum()) // int(far.sum()), int(dv[far].sum()) // int(far.sum()), reach


def _run_centre(line: np.ndarray, dark: np.ndarray, v_pred: int
                ) -> tuple[int, int] | None:
    """(centre_q4, length_q4) of the dark run in a column nearest the predicted row."""
    n = len(line)
    v = min(n - 1, max(0, v_pred))
    best = None
    for d in range(0, n):
        for r in (v - d, v + d):
            if 0 <= r < n and dark[r]:
                best = r
                break
        if best is not None or d > 8:
            break
    if best is None:
        return None
    top = best
    while top > 0 and dark[top - 1]:
        top -= 1
    bot = best
    while bot < n - 1 and dark[bot + 1]:
        bot += 1
    tq = db.edge_q4(line, top, -1)
    bq = db.edge_q4(line, bot, +1)
    if tq is None or bq is None:
        return None
    return (tq + bq) // 2, bq - tq


def _scan_arm(grey: np.ndarray, dark: np.ndarray, p: Plus, side: int, slope_q12: int | None,
              arms: dict) -> tuple[list[tuple[int, int]], list[int], OpCounts]:
    """Central points and run lengths on one side arm (side -1 left, +1 right), the line to
    follow predicted from the arm's pixels or, on the second pass, from ``slope_q12``.
    ``arms`` keeps each side's direction between the two passes."""
    x, y, w, h = p.box
    ops = OpCounts()
    if side not in arms:
        sel = dark[y:y + h, x:x + w].astype(bool)
        # two passes over the box (the reach, then the far cone's sums), ~40 cycles per pixel
        # each as emulated (hostc/spoke.c, docs/budget.md): the local mask tested in place
        # (window bounds, a grey byte), the offset from the centre times the side, the cone
        ops = OpCounts(pixels_read=2 * w * h, alu=54 * w * h, branches=4 * w * h,
                       muls=3 * w * h, divs=2)
        arms[side] = _arm_direction(sel, x, y, p.u_q4, p.v_q4, side)
    arm = arms[side]
    if arm is None:
        return [], [], ops
    adu, adv, reach = arm
    if slope_q12 is not None:
        adu, adv = 4096, side * slope_q12
    pts: list[tuple[int, int]] = []
    runs: list[int] = []
    H, W = grey.shape
    for j in range(K_S):
        # 0.50 .. 0.62 of the reach: beyond the corner where this spoke meets the next and
        # short of its slanted tip for turns up to 30 degrees (corner at 0.46, tip at 0.66)
        off = reach * (50 + 3 * j) // 100
        u = (p.u_q4 + 8) // 16 + side * off
        if not 0 <= u < W:
            return [], [], ops
        v_pred = (p.v_q4 + fp.div_round(16 * off * adv, adu)) // 16
        col = grey[:, u]
        rc = _run_centre(col, dark[:, u], v_pred)
        if rc is None:
            return [], [], ops + _COLUMN_OPS.scaled(j + 1)
        pts.append((16 * u, rc[0]))
        runs.append(rc[1])
    runs.append(reach)  # last entry: the arm's reach in px, for the cross check
    return pts, runs, ops + _COLUMN_OPS.scaled(K_S)


def _is_cross(grey: np.ndarray, t: int, uc_q4: int, vc_q4: int, angle_mrad: int,
              reach: int) -> bool:
    """The "+" template: dark on all four spokes at 0.6 of the reach, light between them
    (diagonals at 0.75 of the reach); a box corner or a bar has no such pattern."""
    H, W = grey.shape
    c, s = fp.cos_q12(angle_mrad), fp.sin_q12(angle_mrad)
    for k in range(8):
        if k < 4:  # spokes: along (c, s) and (-s, c), both signs
            du, dv = ((c, s), (-s, c), (-c, -s), (s, -c))[k]
            r = 6 * reach
        else:  # diagonals between spokes, at 45 degrees: (c - s, s + c) / sqrt(2) etc.
            du, dv = ((c - s, s + c), (-c - s, -s + c), (-c + s, -s - c), (c + s, s - c))[k - 4]
            r = 75 * reach // 10 * 2896 // 4096  # 0.75 reach, 1/sqrt(2) in Q12
        u = (uc_q4 + (16 * r * du) // (10 * 4096) + 8) // 16
        v = (vc_q4 + (16 * r * dv) // (10 * 4096) + 8) // 16
        if not (0 <= u < W and 0 <= v < H):
            return False
        if (int(grey[v, u]) < t) != (k < 4):
            return False
    return True


def _template(grey: np.ndarray, dark: np.ndarray, p: Plus, slope_q12: int | None,
              arms: dict):
    """One pass of the Fig. 3 template on both side arms: (points left, points right, runs,
    k_l, reach px) or None."""
    pts_l, runs_l, ops = _scan_arm(grey, dark, p, -1, slope_q12, arms)
    pts_r, runs_r, o = _scan_arm(grey, dark, p, +1, slope_q12, arms)
    ops += o
    if len(pts_l) != K_S or len(pts_r) != K_S:
        return None, ops
    reach = (runs_l.pop() + runs_r.pop()) // 2
    # a column near the centre of a turned "+" also cuts the neighbouring spoke (a longer run),
    # one near the tip cuts the slanted end (a shorter run): keep runs within 0.85-1.3 of the
    # median (>= 3 per arm)
    med = sorted(runs_l + runs_r)[K_S]
    keep_l = [i for i in range(K_S) if 17 * med <= 20 * runs_l[i] <= 26 * med]
    keep_r = [i for i in range(K_S) if 17 * med <= 20 * runs_r[i] <= 26 * med]
    if len(keep_l) < 3 or len(keep_r) < 3:
        return None, ops
    pts_l = [pts_l[i] for i in reversed(keep_l)]  # left to right
    pts_r = [pts_r[i] for i in keep_r]
    runs = [runs_l[i] for i in keep_l] + [runs_r[i] for i in keep_r]
    # k_l: least-squares slope through all central points of both arms. The paper's mean of
    # the k_b between neighbouring points telescopes to the two end points of one arm, a short
    # baseline that turns 0.1 px of noise into ~1 degree; the two arms are one straight line
    # through the centre, so the fit has a baseline over twice the arm's reach.
    pts = pts_l + pts_r
    n = len(pts)
    su, sv = sum(u for u, _ in pts), sum(v for _, v in pts)
    suu = sum((n * u - su) ** 2 for u, _ in pts)
    suv = sum((n * u - su) * (n * v - sv) for u, v in pts)
    if suu == 0:
        return None, ops
    k_l = fp.div_round(suv << 12, suu)
    # every point on that line within 1.5 px, or this is not one straight spoke
    worst = max(abs(n * v - sv - fp.div_round(k_l * (n * u - su), 4096)) for u, v in pts)
    ops += OpCounts(divs=n + 1, muls32=6 * n, alu=12 * n + 8 * K_S, branches=4 * K_S)
    if worst > n * 24:
        return None, ops
    return (pts_l, pts_r, runs, k_l, reach), ops


def min_ops(height: int, width: int) -> OpCounts:
    """Operation counts :func:`detect_spoke` charges at least for any ``height x width``
    frame: the shared front end (grey, dark mask, labelling), paid before any early return;
    everything after it only adds counts. A lower bound of the modelled time (host/app.py)."""
    return db.front_end_min_ops(height, width)


def detect_spoke(rgb: np.ndarray) -> tuple[Spoke | None, OpCounts]:
    """Measure the spoke of the "+" nearest the image centre; ``(None, ops)`` if none is seen."""
    grey, mask, _, labels, stats, ops = db.dark_components(rgb, "detect_spoke")
    plus, o = plus_candidates(grey, labels, stats)
    ops += o + _CALL_OPS
    if not plus:
        return None, ops
    H, W = grey.shape
    cu, cv = 8 * W, 8 * H
    p = min(plus, key=lambda q: (q.u_q4 - cu) ** 2 + (q.v_q4 - cv) ** 2)
    ops += OpCounts(muls32=2 * len(plus), alu=4 * len(plus))
    # local dark mask of this "+": the mid level between its print and the card around it
    x, y, w, h = p.box
    x0, y0, x1, y1 = max(0, x - 4), max(0, y - 4), min(W, x + w + 4), min(H, y + h + 4)
    roi = grey[y0:y1, x0:x1]
    t = (int(roi.min()) + int(roi.max())) // 2
    dark = np.zeros_like(mask)
    dark[y0:y1, x0:x1] = roi < t
    ops += OpCounts(pixels_read=3 * roi.size, pixels_written=roi.size, alu=3 * roi.size)
    arms: dict = {}
    first, o = _template(grey, dark, p, None, arms)
    ops += o
    if first is None:
        return None, ops
    # second pass: follow the line found by the first, for a turned "+" (beyond ~10 degrees
    # the arm's pixel centroid can mislead the first guess into the neighbouring spoke)
    found = first
    if abs(first[3]) > SECOND_PASS_Q12:
        found, o = _template(grey, dark, p, first[3], arms)
        ops += o
        if found is None:
            return None, ops
    pts_l, pts_r, runs, k_l, reach = found
    angle = fp.atan2_mrad(k_l, 4096)
    if abs(angle) > MAX_ANGLE_MRAD:
        return None, ops
    if not _is_cross(grey, t, p.u_q4, p.v_q4, angle, reach):
        return None, ops
    ops += OpCounts(pixels_read=8, alu=40, muls32=16) + fp.sin_ops().scaled(2)
    run = sum(runs) // len(runs)
    if not 40 * reach <= 100 * run // 16 <= 90 * reach:
        return None, ops  # spoke width 6 mm over reach 8.5-9.5 mm (0.63-0.71), seen as 0.4-0.9
    width = fp.div_round(run * 4096, fp.isqrt(4096 * 4096 + k_l * k_l))
    ops += OpCounts(divs=2 * K_S + 2, muls32=4, alu=40) + fp.atan2_ops().scaled(3) \
        + fp.isqrt_ops(1 << 26)
    return Spoke(p.u_q4, p.v_q4, tuple(pts_l + pts_r), k_l, angle, width), ops
