"""Red cylinder with two black rings of paper 002 (§2.2), integer only.

Step 1 of 002 §2.2: the region of interest (ROI) by colour, its centre (u_c, v_c) taken as the
target's centre. Step 2: scan the ROI perpendicular to the black rings (the cylinder stands
upright, so down the image columns) and measure the pixel spacing d_pixel of the two rings,
which gives the distance D_OC = D f / d_pixel (host.ranging, D = 14.5 mm).

How we do it:

1. Redness ``R - max(G, B)`` on every second pixel of every second row (a 160x120 grid);
   ``redness >= T_RED`` and ``2 R >= 5 max(G, B)`` is red. Colour differences and ratios scale
   with the exposure, so the thresholds hold from 0.7x to 1.3x brightness.
2. The black rings cut the cylinder's red into stacked pieces: 8-connected red components
   whose column ranges overlap by at least half of the narrower one are merged into one
   candidate ROI (the biggest first); the scan columns are those common to all its pieces and,
   among them, the run around the tallest red column (a red object touching one piece
   widens the ROI, not the scan columns).
3. In the central half of the scan columns, the mean redness of each full-resolution row is a
   profile (red-hued pixels only); a ring is a run of rows below half the median red level
   with red rows above and below it, and dark (R at most 2/3 of the red rows'). Exactly two
   rings are required; anything red without them (clutter) is rejected. Each ring's row is
   the darkness-weighted centroid of its run (sub-pixel, Q4).
4. The rings' own columns: on each ring row, the longest run of columns where the ring is
   clearly less red than the red band between the rings (and the red outside them). The
   rings exist only on the cylinder, so this is its width whatever red stands beside it.
   The ring rows are measured again on the central half of that run. The silhouette is the
   red run between the rings through it, each side trusted only if it is about as far out as
   the other (else the nearer side is mirrored: a red neighbour touches the far one). u_c is
   the silhouette's middle (the axis), v_c the midpoint of the rings; the ROI box is returned
   as well.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from mobigrasp.host import fixedpoint as fp
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.vision import dark_blobs as db

T_RED = 40  # redness threshold: red paint ~120-200, black rings / floor / sky < 15
MIN_AREA_HALF_PX = 6  # smallest red piece kept on the 160x120 grid
MIN_RING_GAP_PX = 2  # rings closer than this are not resolved


@dataclass(frozen=True)
class RedCylinderResult:
    """Centre, ring rows and ring spacing in Q4 pixels; ROI (x, y, w, h) in pixels."""

    u_c_q4: int
    v_c_q4: int
    ring1_v_q4: int  # upper ring in the image
    ring2_v_q4: int
    d_pixel_q4: int
    width_q4: int  # red extent between the rings: the cylinder's diameter in pixels
    roi: tuple[int, int, int, int]


def _check(rgb: np.ndarray) -> None:
    if not isinstance(rgb, np.ndarray) or rgb.dtype != np.uint8 or rgb.ndim != 3 \
            or rgb.shape[2] != 3 or rgb.shape[0] < 8 or rgb.shape[1] < 8:
        raise ValueError("detect_red_cylinder: expected an (H, W, 3) uint8 RGB frame, got "
                         f"{getattr(rgb, 'shape', None)} {getattr(rgb, 'dtype', type(rgb))}")


def redness(rgb: np.ndarray) -> np.ndarray:
    """``R - max(G, B)`` clipped at 0, uint8 (saturating integer subtracts)."""
    return cv2.subtract(rgb[..., 0], cv2.max(rgb[..., 1], rgb[..., 2]))


def red_mask(rgb: np.ndarray) -> np.ndarray:
    """Red paint: ``R - max(G, B) >= T_RED`` and ``2 R >= 5 max(G, B)`` (hue close to red,
    so orange and pink are not red), uint8 0/1."""
    gb = cv2.max(rgb[..., 1], rgb[..., 2])
    r = rgb[..., 0]
    ok = (cv2.subtract(r, gb) >= T_RED) & (2 * r.astype(np.int16) >= 5 * gb.astype(np.int16))
    return ok.astype(np.uint8)


def _candidates(mask: np.ndarray) -> tuple[list[tuple[int, ...]], OpCounts]:
    """Merge vertically stacked red components; returns [(area, x0, y0, x1, y1, ix0, ix1)] on
    the grid, biggest first: the union box and the columns common to all merged pieces (the
    cylinder's own columns even when a red object touches one piece)."""
    n, _, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    comps = [(int(stats[i, cv2.CC_STAT_AREA]), int(stats[i, cv2.CC_STAT_LEFT]),
              int(stats[i, cv2.CC_STAT_TOP]),
              int(stats[i, cv2.CC_STAT_LEFT] + stats[i, cv2.CC_STAT_WIDTH]),
              int(stats[i, cv2.CC_STAT_TOP] + stats[i, cv2.CC_STAT_HEIGHT]))
             for i in range(1, n) if stats[i, cv2.CC_STAT_AREA] >= MIN_AREA_HALF_PX]
    comps.sort(key=lambda c: (-c[0], c[1], c[2]))
    used = [False] * len(comps)
    out = []
    for i, seed in enumerate(comps):
        if used[i]:
            continue
        used[i] = True
        area, x0, y0, x1, y1 = seed
        ix0, ix1 = x0, x1
        changed = True
        while changed:  # grow until no piece joins (pieces stack: top, middle, bottom)
            changed = False
            for j, c in enumerate(comps):
                if used[j]:
                    continue
                overlap = min(ix1, c[3]) - max(ix0, c[1])
                if 2 * overlap >= min(ix1 - ix0, c[3] - c[1]):
                    used[j] = True
                    area += c[0]
                    x0, y0, x1, y1 = min(x0, c[1]), min(y0, c[2]), max(x1, c[3]), max(y1, c[4])
                    ix0, ix1 = max(ix0, c[1]), min(ix1, c[3])
                    changed = True
        out.append((area, x0, y0, x1, y1, ix0, ix1))
    out.sort(key=lambda c: -c[0])
    # the red grid is labelled by the same block labelling as the dark mask (hostc/label.c)
    ops = db.components_cost(mask.size)
    ops += OpCounts(alu=10 * len(comps) ** 2 + 10, branches=2 * len(comps) ** 2)
    return out, ops


def _tall_columns(mask: np.ndarray, x0: int, y0: int, x1: int, y1: int, ix0: int, ix1: int
                  ) -> tuple[int, int]:
    """Within the common columns [ix0, ix1), the run of columns around the tallest one whose
    red count is at least half of it: the cylinder, not a flat red thing touching it."""
    if ix1 - ix0 < 2:
        return ix0, ix1
    counts = mask[y0:y1, ix0:ix1].sum(axis=0, dtype=np.int32)
    top = int(np.argmax(counts))
    low = np.flatnonzero(2 * counts < int(counts[top]))
    a = int(low[low < top].max()) + 1 if (low < top).any() else 0
    b = int(low[low > top].min()) if (low > top).any() else ix1 - ix0
    return ix0 + a, ix0 + b


def _rings(profile: np.ndarray) -> tuple[list[tuple[int, int]], int] | None:
    """Runs of rows (start, end exclusive) darker than half the red level, inside red rows."""
    level = int(np.median(profile))
    thr = level // 2
    if level < T_RED:
        return None
    dark = profile < thr
    red_rows = np.flatnonzero(~dark)
    if red_rows.size < 2:
        return None
    lo, hi = int(red_rows[0]), int(red_rows[-1])
    runs = []
    r = lo
    while r <= hi:
        if dark[r]:
            s = r
            while r <= hi and dark[r]:
                r += 1
            runs.append((s, r))
        else:
            r += 1
    return runs, level


def _centroid_q4(profile: np.ndarray, s: int, e: int, level: int) -> int:
    """Darkness-weighted row of a ring run (one row of margin each side for blurred edges)."""
    a, b = max(0, s - 1), min(profile.size, e + 1)
    w = np.maximum(0, level - profile[a:b]).astype(np.int64)
    rows = np.arange(a, b, dtype=np.int64)
    tot = int(w.sum())
    if tot == 0:
        return ((s + e - 1) * 16) // 2
    return fp.div_round(int((w * rows).sum()) * 16, tot)


def _measure(rgb: np.ndarray, y0: int, y1: int, cx0: int, cx1: int
             ) -> tuple[tuple[int, int, int, int, int] | None, OpCounts]:
    """Ring rows in columns [cx0, cx1) of rows [y0, y1): ((r1_q4, r2_q4, level, run1 length,
    run2 length), ops) with rows in full-frame Q4; None and the ops of the scan without exactly
    two thin rings (a failed scan costs as much as the C ran)."""
    roi = rgb[y0:y1, cx0:cx1]
    gb = cv2.max(roi[..., 1], roi[..., 2]).astype(np.int32)
    r = roi[..., 0].astype(np.int32)
    # redness of red-hued pixels only: pink, orange or grey between two red things is no ring
    red = np.where(2 * r >= 5 * gb, r - gb, 0)
    profile = red.sum(axis=1) // (cx1 - cx0)
    r_prof = r.sum(axis=1) // (cx1 - cx0)
    n = red.size
    ops = OpCounts(pixels_read=3 * n, alu=9 * n, muls=n, divs=2 * (y1 - y0),
                   bytes_streamed=3 * n, branches=2 * (y1 - y0))
    found = _rings(profile)
    if found is None or len(found[0]) != 2:
        return None, ops
    ((s1, e1), (s2, e2)), level = found
    # the rings are black: their darkest row has at most 2/3 of the red rows' R
    r_level = int(np.median(r_prof))
    if 3 * int(r_prof[s1:e1].min()) > 2 * r_level or 3 * int(r_prof[s2:e2].min()) > 2 * r_level:
        return None, ops
    ops += OpCounts(alu=8 * (e2 - s1 + 4) + 40, muls32=2 * (e2 - s1 + 4), divs=2)
    r1 = y0 * 16 + _centroid_q4(profile, s1, e1, level)
    r2 = y0 * 16 + _centroid_q4(profile, s2, e2, level)
    if r2 - r1 < MIN_RING_GAP_PX * 16 or 2 * max(e1 - s1, e2 - s2) * 16 > r2 - r1:
        return None, ops  # rings must be thin compared with their spacing (3 mm vs 14.5 mm)
    return (r1, r2, level, e1 - s1, e2 - s2), ops


def _ring_columns(rgb: np.ndarray, x0: int, x1: int, r1_q4: int, r2_q4: int, level: int
                  ) -> tuple[tuple[int, int] | None, OpCounts]:
    """Columns [left, right] of the rings: the longest run of columns where each ring is at
    least level/4 less red than the red band between the rings (and than the red half a
    spacing outside it, when in the frame). Per column the ring is the least red row within a
    quarter spacing of the ring row (perspective slants the rings near the image edges). The
    rings exist only on the cylinder, so a red neighbour (or the background) never widens it."""
    h = rgb.shape[0]
    k = max(1, (r2_q4 - r1_q4 + 16) >> 5)  # half the spacing, whole rows
    j = max(1, k // 2)
    ra, rb = (r1_q4 + 8) >> 4, (r2_q4 + 8) >> 4
    mid = (ra + rb) >> 1
    lo, hi = max(0, ra - k - j), min(h, rb + k + j + 1)
    red = redness(rgb[lo:hi, x0:x1]).astype(np.int16)
    ok = np.ones(x1 - x0, bool)
    for ring, outer in ((ra, ra - k), (rb, rb + k)):
        dark = red[max(0, ring - j - lo):ring + j + 1 - lo].min(axis=0)
        ref = red[mid - lo]
        if lo <= outer < hi:
            ref = np.minimum(ref, red[max(lo, outer - j) - lo:outer + j + 1 - lo].max(axis=0))
        ok &= ref - dark >= level // 4
    n = red.size
    ops = OpCounts(pixels_read=3 * n, alu=6 * n, branches=x1 - x0)
    if not ok.any():
        return None, ops
    # longest run of True: starts and ends of runs from the padded difference
    d = np.diff(np.concatenate(([0], ok.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
    i = int(np.argmax(ends - starts))
    return (x0 + int(starts[i]), x0 + int(ends[i]) - 1), ops


def _red_run(rgb: np.ndarray, ya: int, yb: int, x0: int, x1: int, centre: int
             ) -> tuple[int, int, OpCounts]:
    """Columns of the red run through ``centre`` on rows [ya, yb) (majority red per column)."""
    ya, yb = max(0, ya), max(ya + 1, yb)
    band = redness(rgb[ya:yb, x0:x1]) >= T_RED
    colred = band.sum(axis=0) * 2 >= band.shape[0]
    ops = OpCounts(pixels_read=3 * band.size, alu=5 * band.size, branches=band.shape[1])
    c = centre - x0
    gaps = np.flatnonzero(~colred)
    left = int(gaps[gaps < c].max()) + 1 if (gaps < c).any() else 0
    right = int(gaps[gaps > c].min()) - 1 if (gaps > c).any() else colred.size - 1
    return x0 + left, x0 + right, ops


def min_ops(height: int, width: int) -> OpCounts:
    """Operation counts :func:`detect_red_cylinder` charges at least for any ``height x width``
    frame: the red mask on the half-resolution grid and the labelling of its components (at
    least the constant of the merge), paid before the candidate loop; everything after only
    adds counts. A lower bound of the modelled time (host/app.py)."""
    h, w = int(height), int(width)
    m = ((h + 1) // 2) * ((w + 1) // 2)  # rgb[::2, ::2]
    return red_grid_ops(h, w) + db.components_cost(m) + OpCounts(alu=10)


def red_grid_ops(height: int, width: int) -> OpCounts:
    """The red mask on the half-resolution grid: three byte loads, max, subtract, the hue test
    and a store per grid pixel; every other row of the frame comes from SDRAM (the grid reads
    every line of those rows)."""
    h, w = int(height), int(width)
    m = ((h + 1) // 2) * ((w + 1) // 2)
    return OpCounts(pixels_read=3 * m, pixels_written=m, alu=7 * m, muls=m,
                    bytes_streamed=(h + 1) // 2 * w * 3)


def detect_red_cylinder(rgb: np.ndarray) -> tuple[RedCylinderResult | None, OpCounts]:
    """Find the 002 red cylinder and its two black rings; ``(None, ops)`` when not found."""
    _check(rgb)
    h, w = rgb.shape[:2]
    small = rgb[::2, ::2]
    mask = red_mask(small)
    ops = red_grid_ops(h, w)
    cands, o = _candidates(mask)
    ops += o
    for _, gx0, gy0, gx1, gy1, gix0, gix1 in cands[:3]:
        # grid box -> full resolution, one grid step of margin (the grid skips odd pixels)
        x0, y0 = max(0, 2 * gx0 - 2), max(0, 2 * gy0 - 2)
        x1, y1 = min(w, 2 * gx1 + 2), min(h, 2 * gy1 + 2)
        gix0, gix1 = _tall_columns(mask, gx0, gy0, gx1, gy1, gix0, gix1)
        ops += OpCounts(pixels_read=(gx1 - gx0) * (gy1 - gy0), alu=2 * (gx1 - gx0) * (gy1 - gy0))
        ix0, ix1 = 2 * gix0, min(w, 2 * gix1)
        if ix1 - ix0 < 4 or y1 - y0 < 4:
            continue
        # pass 1: rings in the central half of the scan columns; if a red neighbour spoils
        # them, in narrow strips of the ROI, nearest the scan centre first
        cx0, cx1 = ix0 + (ix1 - ix0) // 4, ix1 - (ix1 - ix0) // 4
        m, o = _measure(rgb, y0, y1, cx0, cx1)
        ops += o
        if m is None:
            sw = max(4, (x1 - x0) // 8)
            mid = (cx0 + cx1) // 2
            for sx in sorted(range(x0, x1 - sw + 1, sw // 2), key=lambda a: abs(a + sw // 2 - mid)):
                m, o = _measure(rgb, y0, y1, sx, sx + sw)
                ops += o
                if m is not None:
                    cx0, cx1 = sx, sx + sw
                    break
        if m is None:
            continue
        r1, r2, level, _, _ = m
        # the rings' own columns: the cylinder's width and axis, whatever red is beside it
        cols, o = _ring_columns(rgb, x0, x1, r1, r2, level)
        ops += o
        if cols is None or cols[1] - cols[0] < 3:
            continue
        left, right = cols
        r1, r2, _, e1, e2 = m
        # silhouette: the red run between the rings through the rings' columns; the rings fade
        # a little before the silhouette edges, so their run is a bit narrower. A side whose
        # red reaches much further out than the other is a red neighbour: mirror the other.
        red_l, red_r, o = _red_run(rgb, (r1 >> 4) + e1, (r2 >> 4) - e2 + 1, x0, x1,
                                   (left + right) // 2)
        ops += o
        ml, mr = left - red_l, red_r - right
        if abs(ml - mr) > max(3, (right - left) // 8):
            ml = mr = max(0, min(ml, mr))  # one side runs on into a red neighbour
        left, right = left - ml, right + mr
        if left <= 0 or right >= w - 1:
            continue  # cut by the image border: the axis cannot be located, say not found
        q = (right - left + 1) // 4
        if abs(left + q - cx0) + abs(right + 1 - q - cx1) > max(2, q // 2):
            # pass 2: pass 1 scanned columns off the cylinder's (a red neighbour was merged);
            # measure the rings again on the central half of the silhouette
            m, o = _measure(rgb, y0, y1, left + q, right + 1 - q)
            ops += o
            if m is None:
                continue
            r1, r2, _, _, _ = m
        u_c = (left + right) * 8  # (left + right) / 2 in Q4
        res = RedCylinderResult(u_c, (r1 + r2 + 1) >> 1, r1, r2, r2 - r1,
                                (right - left + 1) * 16, (x0, y0, x1 - x0, y1 - y0))
        return res, ops
    return None, ops


RING_D_MM_Q4 = 232  # 14.5 mm in Q4: the spacing D of the two rings (002 §4)
RED_CYL_HEIGHT_MM_Q4 = 1920  # 120 mm in Q4: the cylinder's height (docs/markers.md)
MIN_ROI_AREA_HALF_PX = 12  # the colour ROI alone: a red region this big on the grid (48 px)


@dataclass(frozen=True)
class RedRoi:
    """Step 1 of 002 §2.2 alone: the colour ROI (x, y, w, h in px) of the biggest stacked red
    region, its centre (u_c, v_c) in Q4 px and its red area in px; ``touches_edge`` when the
    box meets the top or bottom row of the frame (its height is then not the cylinder's)."""

    u_c_q4: int
    v_c_q4: int
    roi: tuple[int, int, int, int]
    area_px: int
    touches_edge: bool


def detect_red_roi(rgb: np.ndarray) -> tuple[RedRoi | None, OpCounts]:
    """The red region of interest of 002 §2.2 step 1, without the rings of step 2: what the
    red cylinder gives where its rings are not resolved (far) or not all in view (close); any
    red region of that size is one, so it is a bearing to steer on, not evidence of the
    cylinder. u_c is the middle of the columns common to the stacked red pieces."""
    _check(rgb)
    h, w = rgb.shape[:2]
    mask = red_mask(rgb[::2, ::2])
    ops = red_grid_ops(h, w)
    cands, o = _candidates(mask)
    ops += o + OpCounts(alu=12)
    if not cands or cands[0][0] < MIN_ROI_AREA_HALF_PX:
        return None, ops
    area, gx0, gy0, gx1, gy1, gix0, gix1 = cands[0]
    # grid cell k covers full-resolution pixels 2k, 2k + 1: a run [a, b) of cells spans
    # [2a, 2b) px, its middle at a + b - 1/2 px
    u_c = (gix0 + gix1) * 16 - 8
    v_c = (gy0 + gy1) * 16 - 8
    roi = (2 * gx0, 2 * gy0, 2 * (gx1 - gx0), 2 * (gy1 - gy0))
    edge = gy0 == 0 or gy1 >= mask.shape[0]
    return RedRoi(u_c, v_c, roi, 4 * area, edge), ops


def roi_min_ops(height: int, width: int) -> OpCounts:
    """What :func:`detect_red_roi` charges at least: the red grid and its labelling."""
    return min_ops(height, width)


def roi_sighting(res: RedRoi, f_px: int) -> tuple[int, int, int] | None:
    """The ROI's centre (Q4 px) and a depth from its height, the cylinder's 120 mm seen
    ``h`` px tall (pinhole, as D_OC of 002 §4 with the height for D); None when the box meets
    the frame's top or bottom (the height is cut) or is too flat to be the standing
    cylinder. Ours, not 002's: far away the rings are not resolved."""
    _, _, w_px, h_px = res.roi
    if res.touches_edge or h_px <= 0 or 2 * h_px < 3 * w_px // 2:
        return None
    return res.u_c_q4, res.v_c_q4, RED_CYL_HEIGHT_MM_Q4 * f_px // h_px


def sighting(res: RedCylinderResult, f_px: int) -> tuple[int, int, int] | None:
    """The cylinder's centre (Q4 px) and its depth D_OC = D f / d_pixel (Q4 mm, 002 §4), the
    distance used as the depth: the generic pinhole target (host/task/sense.py). The 002 task
    places the cylinder by host.ranging.locate_ring_pair instead, and uses this only with the
    wrist rolled (host/task/method002.py ``object_position``)."""
    if res.d_pixel_q4 <= 0:
        return None
    return res.u_c_q4, res.v_c_q4, RING_D_MM_Q4 * f_px * 16 // res.d_pixel_q4
