"""Radial symbol of paper 000 (§III.A): centre (u_r, v_r), ring diameter d_p + d_rp and the
object position ``Y_oc = L f / (d_p + d_rp)``, ``X_oc = (u0 - u_r) Y_oc / f``,
``Z_oc = (v0 - v_r) Y_oc / f`` (L = 109 mm, f = 611 px). Integer only.

Used far from the object (search and Bezier planning; docs/markers.md): the object top is seen
obliquely, so the dual outer rings appear as an ellipse whose horizontal width is the ring's
diameter (the camera does not roll while searching). Steps:

1. grey, global dark threshold, 8-connected dark components (host.vision.dark_blobs);
2. ring test per component: wide enough, partly filled, and its bounding-box centre is a light
   pixel enclosed by the component (a light 4-connected region that does not reach the box's
   border) — a closed ring around a light centre, which solid clutter never has;
3. the outermost passing ring; its widest row gives ``d_p + d_rp`` between the sub-pixel outer
   edges (dark/light mid-level crossings), its centre u_r; v_r is the middle of the sub-pixel
   top and bottom outer edges in the column through u_r.

Paper 000 names ``d_p + d_rp`` without defining the two terms; we read them as the diameter
between the ring's centre lines plus one ring width, i.e. the outer diameter, which matches the
physical L = 109 mm (outer edge to outer edge).

Camera axes here follow the paper: Y_oc along the optical axis, X_oc to the left, Z_oc up.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from host import fixedpoint as fp
from host.budget import OpCounts
from host.vision import dark_blobs as db
from host.vision.grey import to_grey

L_MM = 109  # 000 §IV: physical outer diameter of the dual outer rings
F_PX = 611  # 000 §IV
U0_PX = 160
V0_PX = 120
MIN_WIDTH_PX = 12  # narrower rings cannot be measured to 2 %
MAX_CANDIDATES = 40


@dataclass(frozen=True)
class RadialSymbol:
    """Radial symbol seen: pixel centre and diameter in Q4 px, position in mm (paper axes)."""

    u_q4: int
    v_q4: int
    diameter_q4: int  # d_p + d_rp
    y_oc_mm: int  # along the optical axis
    x_oc_mm: int  # to the left
    z_oc_mm: int  # up


def _is_ring(labels: np.ndarray, k: int, x: int, y: int, w: int, h: int
             ) -> tuple[np.ndarray | None, np.ndarray | None, OpCounts]:
    """(component mask, enclosed interior mask, ops) of component k if it is a closed ring.

    The interior is the largest 4-connected non-component region of the box that does not
    reach the box's border, and must hold the box's centre column; so a ring still passes when
    something dark (the object's body) touches it from outside.
    """
    roi = labels[y:y + h, x:x + w] == k
    ops = OpCounts(pixels_read=w * h, alu=w * h)
    light = (~roi).view(np.uint8)
    n, lab, st, _ = cv2.connectedComponentsWithStats(light, connectivity=4, ltype=cv2.CV_32S)
    ops += OpCounts(pixels_read=2 * w * h, pixels_written=w * h, alu=6 * w * h, branches=w * h)
    best, best_area = 0, 0
    for j in range(1, n):
        bx, by, bw, bh, area = (int(v) for v in st[j])
        if bx == 0 or by == 0 or bx + bw == w or by + bh == h:
            continue  # reaches the border: outside, not enclosed
        if area > best_area and bx <= w // 2 < bx + bw:
            best, best_area = j, area
    ops += OpCounts(alu=8 * n, branches=2 * n)
    if best == 0 or best_area < 4 or 25 * best_area < w * h:
        return None, None, ops
    return roi, lab == best, ops


def _row_edges(grey: np.ndarray, roi: np.ndarray, x: int, y: int, r: int
               ) -> tuple[int, int] | None:
    row = roi[r]
    left = int(np.argmax(row))
    right = len(row) - 1 - int(np.argmax(row[::-1]))
    line = grey[y + r]
    lq = db.edge_q4(line, x + left, -1)
    rq = db.edge_q4(line, x + right, +1)
    if lq is None or rq is None:
        return None
    return lq, rq


def _local_ring(grey: np.ndarray, x: int, y: int, w: int, h: int
                ) -> tuple[tuple[np.ndarray, np.ndarray, int, int, int, int, int] | None, OpCounts]:
    """Re-threshold the box around a candidate at the middle of its own dark and light levels
    (the card and the print), so thin far rings are not lost to the global threshold."""
    H, W = grey.shape
    m, mx = max(3, w // 8), w + 3  # a candidate may be one side arc of the ring
    x0, y0, x1, y1 = max(0, x - mx), max(0, y - m), min(W, x + w + mx), min(H, y + h + m)
    roi = grey[y0:y1, x0:x1]
    t = (int(roi.max()) + int(roi.min())) // 2
    mask = (roi < t).view(np.uint8)
    n_lab, labels, stats, ops = db.components(mask)
    ops += OpCounts(pixels_read=2 * roi.size, pixels_written=roi.size, alu=3 * roi.size)
    if n_lab < 2:
        return None, ops
    k = 1 + int(np.argmax(stats[1:, 2]))
    bx, by, bw, bh = (int(v) for v in stats[k, :4])
    if 10 * bw < 8 * w:
        return None, ops
    sel, inner, o = _is_ring(labels, k, bx, by, bw, bh)
    ops += o
    if sel is None:
        return None, ops
    return (sel, inner, x0 + bx, y0 + by, bw, bh, t), ops


def detect_radial_symbol(rgb: np.ndarray, f_px: int = F_PX, u0_px: int = U0_PX,
                         v0_px: int = V0_PX) -> tuple[RadialSymbol | None, OpCounts]:
    """Find the radial symbol; ``(None, ops)`` when no closed ring is seen (never a guess)."""
    db.check_rgb(rgb, "detect_radial_symbol")
    grey, ops = to_grey(rgb)
    mask, t, o = db.dark_mask(grey)
    ops += o
    n_lab, labels, stats, o = db.components(mask)
    ops += o
    st = stats[1:]
    x, y, w, h, area = st[:, 0], st[:, 1], st[:, 2], st[:, 3], st[:, 4]
    ok = (w >= MIN_WIDTH_PX) & (h >= 3) & (10 * w >= 8 * h) & (area * 100 <= 85 * w * h)
    cand = np.flatnonzero(ok)
    ops += OpCounts(alu=10 * len(st), branches=len(st))
    cand = cand[np.argsort(-w[cand], kind="stable")][:MAX_CANDIDATES]  # outermost ring first
    for i in cand:
        found, o = _local_ring(grey, int(x[i]), int(y[i]), int(w[i]), int(h[i]))
        ops += o
        if found is None:
            continue
        roi, inner, xi, yi, wi, hi, _ = found
        widths = roi.shape[1] - np.argmax(roi[:, ::-1], axis=1) - np.argmax(roi, axis=1)
        widths[~roi.any(axis=1)] = 0
        wmax = int(widths.max())
        rows = np.flatnonzero(widths == wmax)
        r0 = int(rows[len(rows) // 2])
        best = None
        for r in (r0 - 1, r0, r0 + 1):
            if 0 <= r < hi:
                e = _row_edges(grey, roi, xi, yi, r)
                ops += db.EDGE_OPS.scaled(2)
                if e is not None and (best is None or e[1] - e[0] > best[1] - best[0]):
                    best = e
        if best is None:
            continue
        d_q4 = best[1] - best[0]
        u_q4 = (best[0] + best[1]) // 2
        # v_r: middle of the enclosed interior in the column through u_r (its top and bottom
        # are the inner edges of the ring, symmetric about the centre; the body below the
        # object top cannot shift them)
        col = inner[:, min(wi - 1, max(0, (u_q4 + 8) // 16 - xi))]
        if not col.any():
            continue
        top = int(np.argmax(col))
        bot = hi - 1 - int(np.argmax(col[::-1]))
        line = grey[:, (u_q4 + 8) // 16]
        tq = db.edge_q4(line, yi + top - 1, +1)
        bq = db.edge_q4(line, yi + bot + 1, -1)
        ops += db.EDGE_OPS.scaled(2)
        if tq is None or bq is None:
            continue
        v_q4 = (tq + bq) // 2
        y_mm = fp.div_round(L_MM * f_px * 16, d_q4)
        x_mm = fp.div_round((u0_px * 16 - u_q4) * y_mm, f_px * 16)
        z_mm = fp.div_round((v0_px * 16 - v_q4) * y_mm, f_px * 16)
        ops += OpCounts(divs=3, muls32=4, alu=12)
        return RadialSymbol(u_q4, v_q4, d_q4, y_mm, x_mm, z_mm), ops
    return None, ops
