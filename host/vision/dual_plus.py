"""Dual "+" symbol of paper 000 (§III.A): centres (u1, v1), (u2, v2) of both "+" and the distance
``D_is = D_act f / d_pixel`` with ``d_pixel = sqrt((u1 - u2)^2 + (v1 - v2)^2)`` (D_act = 47.3 mm),
then ``X'_oc = D_is cos(alpha)``, ``Y'_oc = D_is sin(alpha)``,
``Z'_oc = D_is (u0 - (u1 + u2) / 2) / f`` with ``alpha = theta2 + theta3 + theta4`` (given in
mrad). Integer only.

Used for the approach adjustment (docs/markers.md): the camera looks down at the object top
from 0.2-0.45 m. Steps:

1. grey, global dark threshold, 8-connected dark components (host.vision.dark_blobs);
2. "+" candidates: small dark components, partly filling their box, dark at the centre,
   solidity (area over convex-hull area) 0.45-0.88 — a "+" has four notches, which blobs,
   bars and discs do not — at least 2.2x lighter around (black print on a white card) and
   not cut by the image border;
3. the pair: similar areas (within 2:1: a pair along the line of sight, seen steeply from
   close, differs by more than 1.6:1; docs/task.md "001: the look before the grasp"),
   separation 2-5.5 times the square root of the mean area (47.3 mm apart for 17 mm "+",
   seen at up to 2:1 foreshortening), a light point between them; the pair with the largest
   "+" wins;
4. centres: integer first moments in Q4 px.

Foreshortening (ours, beyond 000): the paper's formula assumes the segment between the "+" is
seen square-on. Seen obliquely it is shortened and D_is comes out too large (by up to 1/sin of
the view elevation). A "+" with equal arms has an isotropic second-moment matrix on the card,
so the image moment matrix C of the two "+" is proportional to A A^T (A: card -> image
Jacobian). The largest singular value of A over the pair's length, i.e.
``d_eff^2 = lambda_max(C) * p^T C^-1 p`` with p the image vector between the centres, is the
pair's image length had it been seen square-on; we use d_eff for ``dist_mm`` and also return
the paper's value ``dist_raw_mm`` from d_pixel.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from mobigrasp.host import fixedpoint as fp
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.vision import dark_blobs as db

D_ACT_DMM = 473  # 000 §IV: D_act = 47.3 mm, in 0.1 mm
F_PX = 611
U0_PX = 160
MIN_AREA_PX = 12
SOLIDITY_MIN_PCT, SOLIDITY_MAX_PCT = 45, 88
SEP_MIN_Q4, SEP_MAX_Q4 = 32, 88  # separation / sqrt(mean area), x16


@dataclass(frozen=True)
class DualPlus:
    """Both "+" centres (Q4 px), their distances and the object position (mm, 000 §III.A)."""

    u1_q4: int
    v1_q4: int
    u2_q4: int
    v2_q4: int
    d_pixel_q4: int  # 000's d_pixel
    d_eff_q4: int  # foreshortening-corrected d_pixel (module docstring)
    dist_mm: int  # D_act f / d_eff
    dist_raw_mm: int  # 000's D_is = D_act f / d_pixel
    x_oc_mm: int  # X'_oc = D_is cos(alpha)
    y_oc_mm: int  # Y'_oc = D_is sin(alpha)
    z_oc_mm: int  # Z'_oc = D_is (u0 - (u1 + u2) / 2) / f

    @property
    def d_is_mm(self) -> int:
        """000's D_is as used downstream: the foreshortening-corrected distance."""
        return self.dist_mm


@dataclass(frozen=True)
class Plus:
    """One "+" candidate: its moments, centre (Q4 px), label and bounding box."""

    m: tuple[int, int, int, int, int, int]  # m00, m10, m01, m20, m11, m02 (px)
    u_q4: int
    v_q4: int
    label: int = 0
    box: tuple[int, int, int, int] = (0, 0, 0, 0)  # x, y, w, h


# offsets of a pixel's four corners (int32, as cv2.convexHull takes points)
_CORNERS = np.array([[0, 0], [1, 0], [0, 1], [1, 1]], np.int32)


def _twice_area(poly: list) -> int:
    """Twice the signed area of a polygon of integer [x, y] vertices (shoelace, plain ints:
    a hull has a few dozen vertices, fewer than numpy's per-call overhead is worth)."""
    s = 0
    px, py = poly[-1]
    for x, y in poly:
        s += px * y - py * x
        px, py = x, y
    return s


def _solidity_pct(sel: np.ndarray) -> tuple[int, OpCounts]:
    """100 x area / convex-hull area of a bool ROI (integer shoelace, hull of pixel corners)."""
    contours, _ = cv2.findContours(sel.view(np.uint8), cv2.RETR_EXTERNAL,
                                   cv2.CHAIN_APPROX_SIMPLE)
    # the board's hull (hostc/dual_plus.c): each box row's leftmost and rightmost pixel, then
    # one monotone chain per side over the row levels, about 40 cycles per row
    ops = OpCounts(alu=28 * sel.shape[0] + 60, branches=4 * sel.shape[0])
    if not contours:
        return 0, ops
    pts = np.concatenate(contours).reshape(-1, 2)
    # pixel squares, not centres: the hull of the corners has the area the pixels cover
    # (all points at the first corner, then all at the second, ...)
    corners = (_CORNERS[:, None, :] + pts[None, :, :]).reshape(-1, 2)
    hull = cv2.convexHull(corners).reshape(-1, 2).tolist()
    area2 = abs(_twice_area(hull))
    if area2 == 0:
        return 0, ops
    return 200 * int(np.count_nonzero(sel)) // area2, ops


def plus_candidates(grey: np.ndarray, labels: np.ndarray, stats: np.ndarray
                     ) -> tuple[list[Plus], OpCounts]:
    """The dark components of a labelled frame that look like a "+" on white (step 2)."""
    H, W = grey.shape
    x, y, w, h, area = (stats[1:, i] for i in range(5))
    ok = (area >= MIN_AREA_PX) & (w >= 4) & (h >= 4) & (w <= W // 2) & (h <= H // 2) \
        & (100 * area >= 25 * w * h) & (100 * area <= 80 * w * h) & (w <= 4 * h) & (h <= 4 * w) \
        & (x > 0) & (y > 0) & (x + w < W) & (y + h < H)  # cut by the border: not a whole "+"
    # the call and the stats scan: about 60 cycles per component (five words read, the size
    # tests, a line fill per 32 bytes of stats), as emulated (docs/budget.md)
    ops = OpCounts(alu=100 + 25 * len(area), branches=4 * len(area), bytes_streamed=20 * len(area))
    out: list[Plus] = []
    # counts kept as plain ints in the loop and charged once (OpCounts additions are slow)
    frame_px = dark_px = 0
    for i in np.flatnonzero(ok)[:64]:
        k = int(i) + 1
        xi, yi, wi, hi = int(x[i]), int(y[i]), int(w[i]), int(h[i])
        if labels[yi + hi // 2, xi + wi // 2] != k:
            continue  # a "+" is dark at its centre
        sel = labels[yi:yi + hi, xi:xi + wi] == k
        sol, o = _solidity_pct(sel)
        ops += o
        if not SOLIDITY_MIN_PCT <= sol <= SOLIDITY_MAX_PCT:
            continue
        # lighter around: the mean of a 2 px frame around the box at least 2.2x the print's
        # (black print on a white card is ~10x; a brown body on the floor is ~1.5x)
        x0, y0, x1, y1 = max(0, xi - 2), max(0, yi - 2), min(W, xi + wi + 2), min(H, yi + hi + 2)
        frame = grey[y0:y1, x0:x1]  # uint8: numpy sums it in 64 bits
        inside = frame[yi - y0:yi - y0 + hi, xi - x0:xi - x0 + wi]
        ring_sum = int(frame.sum()) - int(inside.sum())
        ring_n = frame.size - inside.size
        dark_sum, dark_n = int(inside[sel].sum()), int(np.count_nonzero(sel))
        frame_px += frame.size
        dark_px += dark_n
        if 10 * ring_sum * dark_n < 22 * dark_sum * ring_n:
            continue
        m = db.moments(sel, xi, yi)
        out.append(Plus(m, (16 * m[1] + m[0] // 2) // m[0], (16 * m[2] + m[0] // 2) // m[0], k,
                        (xi, yi, wi, hi)))
    # one pass over the box and its 2 px frame gives the sums of the lightness test and the
    # moments (hostc/dual_plus.c): per pixel a label word and a grey byte read, the in-box and
    # label tests (~30 cycles with the label rows' line fills); per dark pixel the six 64-bit
    # moment sums (~66 cycles); per "+" kept its two rounded centre divisions
    ops += OpCounts(pixels_read=2 * frame_px, alu=16 * frame_px + 36 * dark_px
                    + 1300 * len(out), branches=frame_px, muls32=6 * dark_px,
                    divs=2 * len(out), bytes_streamed=5 * frame_px)
    return out, ops


def _central(p: Plus) -> tuple[int, int, int]:
    """Central second moments (sums of squared deviations, px^2, rounded) of one "+"."""
    m00, m10, m01, m20, m11, m02 = p.m
    return ((m00 * m20 - m10 * m10) // m00, (m00 * m11 - m10 * m01) // m00,
            (m00 * m02 - m01 * m01) // m00)


def _d_eff_q4(a: Plus, b: Plus, du_q4: int, dv_q4: int) -> int | None:
    ca, cb = _central(a), _central(b)
    sa = a.m[0] * a.m[0]
    sb = b.m[0] * b.m[0]
    # sum of both shape matrices, each normalised by its squared area so the nearer "+" does
    # not dominate: scale by sb * sa to stay integer
    xx = ca[0] * sb + cb[0] * sa
    xy = ca[1] * sb + cb[1] * sa
    yy = ca[2] * sb + cb[2] * sa
    det = xx * yy - xy * xy
    if det <= 0:
        return None
    lam2 = xx + yy + fp.isqrt((xx - yy) * (xx - yy) + 4 * xy * xy)  # 2 lambda_max
    quad = yy * du_q4 * du_q4 - 2 * xy * du_q4 * dv_q4 + xx * dv_q4 * dv_q4  # p^T adj(C) p
    return fp.isqrt(lam2 * quad // (2 * det))


_D_EFF_OPS = OpCounts(alu=36000, branches=1700, muls32=24, divs=3)


def min_ops(height: int, width: int) -> OpCounts:
    """Operation counts :func:`detect_dual_plus` charges at least for any ``height x width``
    frame: the shared front end (grey, dark mask, labelling), paid before any early return;
    everything after it only adds counts. A lower bound of the modelled time (host/app.py)."""
    return db.front_end_min_ops(height, width)


def detect_dual_plus(rgb: np.ndarray, alpha_mrad: int = -1571, f_px: int = F_PX,
                     u0_px: int = U0_PX) -> tuple[DualPlus | None, OpCounts]:
    """Find both "+"; ``(None, ops)`` unless a consistent pair is seen (never a guess)."""
    if isinstance(alpha_mrad, bool) or not isinstance(alpha_mrad, int | np.integer):
        raise ValueError(f"detect_dual_plus: alpha_mrad must be an int (mrad), got {alpha_mrad!r}")
    grey, mask, _, labels, stats, ops = db.dark_components(rgb, "detect_dual_plus")
    plus, o = plus_candidates(grey, labels, stats)
    ops += o
    best = None
    for i in range(len(plus)):
        for j in range(i + 1, len(plus)):
            a, b = plus[i], plus[j]
            a0, b0 = a.m[0], b.m[0]
            if 2 * min(a0, b0) < max(a0, b0):
                continue  # the two "+" are the same size (within 2:1 seen obliquely)
            du, dv = a.u_q4 - b.u_q4, a.v_q4 - b.v_q4
            d_q4 = fp.isqrt(du * du + dv * dv)
            r_q4 = fp.isqrt(256 * (a0 + b0) // 2)  # sqrt(mean area) in Q4
            if not SEP_MIN_Q4 * r_q4 <= 16 * d_q4 <= SEP_MAX_Q4 * r_q4:
                continue
            mu, mv = (a.u_q4 + b.u_q4) // 32, (a.v_q4 + b.v_q4) // 32
            if mask[mv, mu]:
                continue  # the card is white between the "+"
            if best is None or a0 + b0 > best[0]:
                best = (a0 + b0, a, b, du, dv, d_q4)
    ops += OpCounts(alu=30 * len(plus) ** 2, muls32=4 * len(plus) ** 2, branches=len(plus) ** 2)
    if best is None:
        return None, ops
    _, a, b, du, dv, d_q4 = best
    if a.u_q4 > b.u_q4:
        a, b = b, a  # "+" 1 is the left one in the image
    d_eff = _d_eff_q4(a, b, du, dv)
    # the moment algebra needs ~150-bit products: on the board 256-bit integers in 32-bit
    # limbs (hostc/dual_plus.c), a bit-serial long division and two digit-by-digit square
    # roots, ~41 k cycles as emulated (docs/budget.md)
    ops += _D_EFF_OPS
    if d_eff is None or d_eff < d_q4 or d_q4 == 0:
        return None, ops
    dist = fp.div_round(D_ACT_DMM * f_px * 16, 10 * d_eff)
    raw = fp.div_round(D_ACT_DMM * f_px * 16, 10 * d_q4)
    c, s = fp.cos_q12(int(alpha_mrad)), fp.sin_q12(int(alpha_mrad))
    x_mm, y_mm = fp.mul_q12(dist, c), fp.mul_q12(dist, s)
    z_mm = fp.div_round(dist * (u0_px * 32 - a.u_q4 - b.u_q4), 32 * f_px)
    ops += fp.sin_ops().scaled(2) + fp.mul_q12_ops(2) + OpCounts(divs=3, muls32=3)
    return DualPlus(a.u_q4, a.v_q4, b.u_q4, b.v_q4, d_q4, d_eff, dist, raw, x_mm, y_mm,
                    z_mm), ops


def sighting(res: DualPlus, f_px: int) -> tuple[int, int, int] | None:
    """The midpoint of the two "+" (Q4 px) and its depth (Q4 mm): the task's target
    (host/task/sense.py). The depth is D_is corrected for foreshortening (``dist_mm``), used
    as the depth along the axis as 000 does."""
    return (res.u1_q4 + res.u2_q4) // 2, (res.v1_q4 + res.v2_q4) // 2, res.dist_mm * 16


def detect_at_pose(rgb: np.ndarray, joints_mrad: tuple[int, ...], cam: tuple[int, int, int]
                   ) -> tuple[DualPlus | None, OpCounts]:
    """:func:`detect_dual_plus` as the host calls it (host/vision/registry.py): the camera's
    pitch alpha = theta2 + theta3 + theta4 (000 §III.A) from the joint angles."""
    q = joints_mrad
    return detect_dual_plus(rgb, alpha_mrad=int(q[2] + q[3] + q[4]), f_px=cam[0], u0_px=cam[1])
