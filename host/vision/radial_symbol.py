"""Radial symbol of paper 000 (§III.A): centre (u_r, v_r), ring diameter d_p + d_rp and the
object position ``Y_oc = L f / (d_p + d_rp)``, ``X_oc = (u0 - u_r) Y_oc / f``,
``Z_oc = (v0 - v_r) Y_oc / f`` (L = 109 mm, f = 611 px). Integer only.

Used far from the object (search and Bezier planning; docs/markers.md): the object top is seen
obliquely, so the dual outer rings appear as an ellipse whose horizontal width is the ring's
diameter (the camera does not roll while searching). Steps:

1. grey, global dark threshold, 8-connected dark components (host.vision.dark_blobs); the
   components at least 12 px wide and not solid are candidates, widest first;
2. around each candidate (widened by its own width: it may be one side arc of the ring) the
   grey is summed over 1x3 pixels (noise down, the thin horizontal far arcs kept) and
   re-thresholded at 1/2, then 1/3, of its own dark-to-light range (and, for a far symbol
   whose card clips at 255, then at 2/3);
3. ring test: the widest local component covering the candidate encloses light regions (not
   reaching its box's border) that hold the box's centre column — a closed ring, which solid
   clutter never is;
4. measure: v_r = middle of the interior in the centre column (sub-pixel inner edges of the
   ring), ``d_p + d_rp`` = the widest of the three rows around v_r between the sub-pixel outer
   edges (dark/light mid-level crossings), u_r its middle, then v_r again through u_r;
5. checks that it is the printed ellipse and nothing merged with it: interior centred on u_r,
   ring as thick left as right, white card beyond both outer edges, ring under half as bright
   as its interior, ring + interior filling 62-84 % of the ring's box (an ellipse: 78.5 %),
   interior 55-90 % of the outer width.

Paper 000 names ``d_p + d_rp`` without defining the two terms; we read them as the diameter
between the ring's centre lines plus one ring width, i.e. the outer diameter, which matches the
physical L = 109 mm (outer edge to outer edge).

Camera axes here follow the paper: Y_oc along the optical axis, X_oc to the left, Z_oc up.

:func:`detect_radial_cut` reads the same front end for a symbol too near to be seen whole: a
ring-like dark component cut by the frame's border (docs/task.md, "000: the back-off from a
symbol cut by the frame").
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from mobigrasp.host import fixedpoint as fp
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.vision import dark_blobs as db

L_MM = 109  # 000 §IV: physical outer diameter of the dual outer rings
F_PX = 611  # 000 §IV
U0_PX = 160
V0_PX = 120
MIN_WIDTH_PX = 12  # narrower rings cannot be measured to 2 %
MAX_CANDIDATES = 12  # widest first; bounds the ARM9 time of a cluttered frame
# local re-thresholding may touch at most 3/2 of a frame's pixels: with the dual "+" before it
# on one frame the radial symbol stays within the frame period (docs/budget.md, "ADJUST")
LOCAL_BUDGET_NUM, LOCAL_BUDGET_DEN = 3, 2
MIN_CONTRAST = 90  # grey levels between print and card at the darkest exposure (0.7 x 235-20)
FILL_MIN_PCT, FILL_MAX_PCT = 62, 84  # ring + interior over the box (ellipse: 78.5 %)
SPAN_MIN_PCT, SPAN_MAX_PCT = 55, 90  # interior width over outer width at the centre row
# a cut symbol: the visible part at least CUT_MIN_PX wide (the whole symbol is wider, so nearer
# than L f / CUT_MIN_PX = 1.04 m), its box at most CUT_SOLID_PCT dark: a ring's arc with the
# light card inside (the cut symbols of docs/task.md's close starts 23-32 %, the clutter of
# camera_views.empty that touches the border 36-70 %)
CUT_MIN_PX = 64
CUT_SOLID_PCT = 45


@dataclass(frozen=True)
class RadialSymbol:
    """Radial symbol seen: pixel centre and diameter in Q4 px, position in mm (paper axes)."""

    u_q4: int
    v_q4: int
    diameter_q4: int  # d_p + d_rp
    y_oc_mm: int  # along the optical axis
    x_oc_mm: int  # to the left
    z_oc_mm: int  # up


@dataclass(frozen=True)
class RadialCut:
    """Dark print cut by the frame's border where a near radial symbol would be: the box (px)
    of the widest such component and the side it is cut at (-1 left, 1 right, 0 top or bottom
    alone)."""

    x: int
    y: int
    w: int
    h: int
    side: int


def _is_ring(labels: np.ndarray, k: int, x: int, y: int, w: int, h: int
             ) -> tuple[np.ndarray | None, np.ndarray | None, OpCounts]:
    """(component mask, enclosed interior mask, ops) of component k if it is a closed ring.

    The interior is the union of the 4-connected non-component regions of the box that do not
    reach the box's border (print inside the ring may split it); it must be a fair part of the
    box and hold the box's centre column. A ring still passes when something dark (the
    object's body) touches it from outside.
    """
    roi = labels[y:y + h, x:x + w] == k
    ops = OpCounts(pixels_read=w * h, alu=w * h)
    light = (~roi).view(np.uint8)
    # labels only (OpenCV's stats pass costs 4x the labelling): a region is enclosed when none
    # of its pixels lies on the box's border, i.e. its bounding box does not reach the border
    n, lab = cv2.connectedComponents(light, connectivity=4, ltype=cv2.CV_32S)
    # as the C finds the interior (hostc/radial_symbol.c, docs/budget.md): a copy of the box,
    # a flood from its border over the light outside (four neighbour tests per pixel, a stack),
    # a count; labels, stack and masks come from SDRAM (about 100 cycles per box pixel)
    ops += OpCounts(pixels_read=7 * w * h, pixels_written=3 * w * h, luts=4 * w * h,
                    alu=37 * w * h, branches=8 * w * h, bytes_streamed=8 * w * h)
    enclosed = np.ones(n, bool)
    enclosed[lab[0]] = False
    enclosed[lab[-1]] = False
    enclosed[lab[:, 0]] = False
    enclosed[lab[:, -1]] = False
    enclosed[0] = False
    ops += OpCounts(alu=8 * n, branches=2 * n)
    # the interior mask, and its area (the areas of the enclosed regions summed), from it
    inner = _label_mask(lab, enclosed)
    total = int(np.count_nonzero(inner))
    if total < 4 or 25 * total < w * h:
        return None, None, ops
    if not inner[:, w // 2].any():  # holds the centre column
        return None, None, ops
    return roi, inner, ops


def _label_mask(lab: np.ndarray, chosen: np.ndarray) -> np.ndarray:
    """``chosen[lab]``: the bool mask of the pixels whose label is chosen. With at most 256
    labels (nearly always: a ring's box holds a few regions) by an OpenCV table look-up on the
    labels as bytes; numpy's gather first converts the int32 labels to intp and costs ~5x more
    (host speed only: the same mask)."""
    if len(chosen) > 256:
        return chosen[lab]
    table = np.zeros(256, np.uint8)
    table[:len(chosen)] = chosen
    return cv2.LUT(lab.astype(np.uint8), table).view(bool)


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


# Local thresholds tried in turn, as fractions of the box's dark-to-light range: the middle
# keeps thin far arcs closed; a lower one separates the ring from a floor that exposure or
# noise brought close to the middle. (Higher ones merge the ring with the floor.) Where the
# card clips at 255 (the box's lightest 1x3 sum at least 3 x 252: noise added after the clip
# takes a few levels off) the clip compresses a thin arc's contrast to the card, and 2/3 is
# tried last for a candidate narrower than CUT_MIN_PX, a symbol beyond ~1 m whose far arcs are
# thin (docs/markers.md, "Camera gain").
LOCAL_FRACTIONS = ((1, 2), (1, 3))
LOCAL_FRACTIONS_CLIPPED = LOCAL_FRACTIONS + ((2, 3),)
CLIPPED_SUM = 3 * 252


def _local_box(grey: np.ndarray, x: int, y: int, w: int, h: int
               ) -> tuple[np.ndarray, int, int, int, int]:
    """The box around a candidate that :func:`_local_ring` re-thresholds, summed over 1x3
    pixels: (sums int16, x0, y0, darkest, lightest). The same for every fraction tried, so it
    is computed once per candidate (host speed; each try is charged for it, as on the board)."""
    H, W = grey.shape
    m, mx = max(3, w // 8), w + 3  # a candidate may be one side arc of the ring
    x0, y0, x1, y1 = max(0, x - mx), max(0, y - m), min(W, x + w + mx), min(H, y + h + m)
    # 1x3 horizontal sum (3x the mean): sensor noise drops by sqrt(3) while the far ring's
    # top and bottom arcs, which run horizontally and may be only ~1 px tall, keep their contrast
    # (one OpenCV box sum without normalisation over the box and a column either side; at the
    # frame's edges the edge column is repeated)
    xa = max(0, x0 - 1)
    summed = cv2.boxFilter(grey[y0:y1, xa:min(W, x1 + 1)], cv2.CV_16S, (3, 1), normalize=False,
                           borderType=cv2.BORDER_REPLICATE)
    roi = summed[:, x0 - xa:x1 - xa]
    lo_f, hi_f, _, _ = cv2.minMaxLoc(roi)
    return roi, x0, y0, int(lo_f), int(hi_f)


def _local_ring(box: tuple[np.ndarray, int, int, int, int], x: int, y: int, w: int, h: int,
                num: int, den: int
                ) -> tuple[tuple[np.ndarray, np.ndarray, int, int, int, int] | None, OpCounts,
                           int]:
    """Re-threshold the box around a candidate (:func:`_local_box`) between its own dark and
    light levels (the print and the card), so thin far rings are not lost to the global
    threshold. The third value is the try's pixel reads for the frame's local budget: 4 per
    box pixel (sums, levels), 2 more for the local labelling, 4 per pixel of the ring test's
    box (a fixed count, not the cost model's, so the budget does not move with the model)."""
    roi, x0, y0, lo, hi = box
    touched = 4 * roi.size
    if hi - lo < 3 * MIN_CONTRAST:
        return None, OpCounts(pixels_read=4 * roi.size, alu=6 * roi.size), touched
    t = lo + (hi - lo) * num // den
    mask = (roi < t).view(np.uint8)
    n_lab, labels, stats, ops = db.components(mask)
    ops += OpCounts(pixels_read=4 * roi.size, pixels_written=roi.size, alu=6 * roi.size, divs=1)
    touched += 2 * roi.size
    if n_lab < 2:
        return None, ops, touched
    # the widest local component that covers the candidate's box centre (not a floor blob
    # that noise made dark beside it)
    sx, sy, sw, sh = stats[:, 0], stats[:, 1], stats[:, 2], stats[:, 3]
    cx, cy = x + w // 2 - x0, y + h // 2 - y0
    cover = (sx <= cx) & (cx < sx + sw) & (sy <= cy) & (cy < sy + sh) & (10 * sw >= 8 * w)
    cover[0] = False
    ops += OpCounts(alu=10 * n_lab, branches=n_lab)
    if not cover.any():
        return None, ops, touched
    k = int(np.flatnonzero(cover)[np.argmax(sw[cover])])
    bx, by, bw, bh = (int(v) for v in stats[k, :4])
    sel, inner, o = _is_ring(labels, k, bx, by, bw, bh)
    ops += o
    touched += 4 * bw * bh
    if sel is None:
        return None, ops, touched
    return (sel, inner, x0 + bx, y0 + by, bw, bh), ops, touched


def _interior_v_q4(grey: np.ndarray, inner: np.ndarray, xi: int, yi: int, u_px: int
                   ) -> int | None:
    """Middle (Q4 px) of the enclosed interior in column u_px: its top and bottom are the inner
    edges of the ring, symmetric about the centre, and the object's body below the top cannot
    shift them."""
    col = inner[:, min(inner.shape[1] - 1, max(0, u_px - xi))]
    if not col.any():
        return None
    top = int(np.argmax(col))
    bot = len(col) - 1 - int(np.argmax(col[::-1]))
    line = grey[:, u_px]
    tq = db.edge_q4(line, yi + top - 1, +1)
    bq = db.edge_q4(line, yi + bot + 1, -1)
    if tq is None or bq is None:
        return None
    return (tq + bq) // 2


def _measure(grey: np.ndarray, found, f_px: int, u0_px: int, v0_px: int
             ) -> tuple[RadialSymbol | None, OpCounts]:
    """Diameter, centre and position of a ring that passed the ring test, or None when it is
    not an ellipse (merged with something beside it).

    The ring is horizontally widest through its centre: v from the interior, then the outer
    width on that row and its neighbours (the widest of the three) gives d_p + d_rp and u_r,
    then v again in the column through u_r.
    """
    roi, inner, xi, yi, wi, hi = found
    ops = OpCounts(pixels_read=roi.size, alu=roi.size, branches=hi) + db.EDGE_OPS.scaled(4)
    v_q4 = _interior_v_q4(grey, inner, xi, yi, xi + wi // 2)
    if v_q4 is None:
        return None, ops
    r0 = (v_q4 + 8) // 16 - yi
    best = None
    for r in (r0 - 1, r0, r0 + 1):
        if 0 <= r < hi and roi[r].any():
            e = _row_edges(grey, roi, xi, yi, r)
            ops += db.EDGE_OPS.scaled(2)
            if e is not None and (best is None or e[1] - e[0] > best[1] - best[0]):
                best = e
    if best is None:
        return None, ops
    d_q4 = best[1] - best[0]
    u_q4 = (best[0] + best[1]) // 2
    v_q4 = _interior_v_q4(grey, inner, xi, yi, (u_q4 + 8) // 16)
    if v_q4 is None or d_q4 < 16 * MIN_WIDTH_PX:
        return None, ops
    # the interior of an ellipse is centred on it: reject a ring merged with something dark
    # beside it (an occluder, a shadow, the floor)
    irow = inner[min(hi - 1, max(0, (v_q4 + 8) // 16 - yi))]
    if not irow.any():
        return None, ops
    il = int(np.argmax(irow))
    ir = wi - 1 - int(np.argmax(irow[::-1]))
    if abs(8 * (2 * xi + il + ir) - u_q4) > 16 * max(2, wi // 12):
        return None, ops
    # and the ring is as thick on the left as on the right (not merged with a dark neighbour)
    tl, tr = 16 * (xi + il) - best[0], best[1] - 16 * (xi + ir)
    if abs(tl - tr) > max(32, (tl + tr) // 4):
        return None, ops
    # the card's white margin lies outside both outer edges: at least 70 % of the interior's
    # light level within 3 px (a dark object touching the ring has the floor beyond it)
    line = grey[min(grey.shape[0] - 1, (v_q4 + 8) // 16)]
    light = int(line[xi + il:xi + ir + 1].max())
    lo_x, hi_x = best[0] // 16, (best[1] + 15) // 16
    outside = [int(line[max(0, lo_x - 3):lo_x + 1].max()),
               int(line[hi_x:min(len(line), hi_x + 4)].max())]
    if 10 * min(outside) < 7 * light:
        return None, ops
    # an ellipse fills pi/4 of its box; the interior spans 0.63-0.85 of the outer width
    # (inside the inner ring, or inside the outer ring when the two are resolved)
    # black print on a white card: the ring is less than half as bright as its interior
    box = grey[yi:yi + hi, xi:xi + wi]
    n_ring, n_in = int(roi.sum()), int(inner.sum())
    if 2 * int(box[roi].sum()) * n_in >= int(box[inner].sum()) * n_ring:
        return None, ops
    ops += OpCounts(pixels_read=roi.size, alu=2 * roi.size, divs=0, muls32=2)
    # rows of the ring only (the body below the top may hang from it): mirror the top about v
    hr = min(hi, max(1, (2 * v_q4 - 32 * yi + 16) // 16 + 1))
    filled = int(roi[:hr].sum()) + int(inner[:hr].sum())
    span = ir - il + 1
    if not (FILL_MIN_PCT * wi * hr <= 100 * filled <= FILL_MAX_PCT * wi * hr
            and SPAN_MIN_PCT * wi <= 100 * span <= SPAN_MAX_PCT * wi):
        return None, ops
    y_mm = fp.div_round(L_MM * f_px * 16, d_q4)
    x_mm = fp.div_round((u0_px * 16 - u_q4) * y_mm, f_px * 16)
    z_mm = fp.div_round((v0_px * 16 - v_q4) * y_mm, f_px * 16)
    ops += OpCounts(divs=3, muls32=4, alu=30, pixels_read=2 * wi)
    return RadialSymbol(u_q4, v_q4, d_q4, y_mm, x_mm, z_mm), ops


def min_ops(height: int, width: int) -> OpCounts:
    """Operation counts :func:`detect_radial_symbol` charges at least for any ``height x width``
    frame: the shared front end (grey, dark mask, labelling), paid before any early return;
    everything after it only adds counts. A lower bound of the modelled time (host/app.py)."""
    return db.front_end_min_ops(height, width)


def detect_radial_symbol(rgb: np.ndarray, f_px: int = F_PX, u0_px: int = U0_PX,
                         v0_px: int = V0_PX) -> tuple[RadialSymbol | None, OpCounts]:
    """Find the radial symbol; ``(None, ops)`` when no closed ring is seen (never a guess)."""
    grey, mask, n_lab, labels, stats, ops = db.dark_components(rgb, "detect_radial_symbol")
    st = stats[1:]
    x, y, w, h, area = st[:, 0], st[:, 1], st[:, 2], st[:, 3], st[:, 4]
    # not solid (a ring's box is at most ~55 % dark even when everything inside merges) and
    # not nearer than 0.3 m
    ok = (w >= MIN_WIDTH_PX) & (h >= 3) & (10 * w >= 8 * h) & (area * 100 <= 70 * w * h) \
        & (4 * w <= 3 * grey.shape[1])
    cand = np.flatnonzero(ok)
    # the candidate scan (hostc/radial_symbol.c): a call's set-up, the filter per component
    # and, with any component, the first line fills of the stats table and candidate list
    ops += OpCounts(alu=100 + 12 * len(st) + (150 if len(st) else 0), branches=2 * len(st))
    cand = cand[np.argsort(-w[cand], kind="stable")][:MAX_CANDIDATES]  # outermost ring first
    budget = LOCAL_BUDGET_NUM * grey.size // LOCAL_BUDGET_DEN  # a cluttered frame's bound
    for i in cand:
        xi, yi, wi, hi = int(x[i]), int(y[i]), int(w[i]), int(h[i])
        box = _local_box(grey, xi, yi, wi, hi)
        # the 1x3 sums with the clamped edge columns and the min/max pass, once per candidate
        # (hostc/radial_symbol.c; the grey rows come from SDRAM)
        n_box = box[0].size
        ops += OpCounts(pixels_read=4 * n_box, pixels_written=n_box, alu=22 * n_box,
                        branches=2 * n_box, bytes_streamed=n_box)
        clipped = box[4] >= CLIPPED_SUM and wi < CUT_MIN_PX
        for num, den in LOCAL_FRACTIONS_CLIPPED if clipped else LOCAL_FRACTIONS:
            found, o, touched = _local_ring(box, xi, yi, wi, hi, num, den)
            ops += o
            budget -= touched // 4
            if budget < 0:
                return None, ops
            if found is None:
                continue
            res, o = _measure(grey, found, f_px, u0_px, v0_px)
            ops += o
            if res is not None:
                return res, ops
    return None, ops


def detect_radial_cut(rgb: np.ndarray) -> tuple[RadialCut | None, OpCounts]:
    """A radial symbol cut by the frame's border, from the front end's components (step 1 of
    :func:`detect_radial_symbol`): the widest component that touches the border but does not
    span the frame's width, at least CUT_MIN_PX wide and whose box is at most CUT_SOLID_PCT dark
    (a ring's arc with the light card inside, not a blob). Only
    evidence: no position (its centre lies outside the frame)."""
    grey, mask, n_lab, labels, stats, ops = db.dark_components(rgb, "detect_radial_cut")
    H, W = grey.shape
    st = stats[1:]
    x, y, w, h, area = st[:, 0], st[:, 1], st[:, 2], st[:, 3], st[:, 4]
    left, right = x <= 0, x + w >= W
    ok = (w >= CUT_MIN_PX) & (100 * area <= CUT_SOLID_PCT * w * h) \
        & (left | right | (y <= 0) | (y + h >= H)) & ~(left & right)
    # the scan over the component table (hostc/radial_symbol.c mg_radial_cut)
    ops += OpCounts(alu=20 + 14 * len(st), branches=2 * len(st))
    cand = np.flatnonzero(ok)
    if not len(cand):
        return None, ops
    k = int(cand[np.argmax(w[cand])])  # the widest; the first of equals
    side = -1 if left[k] else 1 if right[k] else 0
    return RadialCut(int(x[k]), int(y[k]), int(w[k]), int(h[k]), side), ops


def sighting(res: RadialSymbol, f_px: int) -> tuple[int, int, int] | None:
    """The symbol's centre (Q4 px) and its depth along the optical axis (Q4 mm): the task's
    target (host/task/sense.py); Y_oc is the depth ``L f / (d_p + d_rp)`` computed above."""
    return res.u_q4, res.v_q4, res.y_oc_mm * 16
