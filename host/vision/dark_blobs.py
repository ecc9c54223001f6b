"""Shared integer steps of the paper-000 detectors: input check, dark threshold, dark components,
sub-pixel edges and integer second moments.

All symbols of 000 are black print on a white card, so every detector starts by splitting dark
from light with one global threshold set from the image's bright level (the 99.8th percentile of
the grey histogram scaled by 45/100: it follows exposure changes of ±30 % and keeps the floor,
which is at least 55 % as bright as the card, on the light side; 0.2 % of a 320x240 frame is
150 px, less than the white of a card 1.3 m away). When the bright level clips at 255 (the
card does from a camera gain of ~1.1) the card's level is unknown and 45 % of 255 leaves the
mixed pixels of thin far print light, so the threshold is at least 65/100 of the median level
(the floor, which fills most search frames at ~0.7 of the card's level and still follows the
gain: docs/markers.md, "Camera gain"). Dark pixels are grouped by
``cv2.connectedComponentsWithStats`` (integer labels and stats; the float centroids it also
returns are not used).

Costs are charged per call in :class:`host.budget.OpCounts` by the pixels each step touches.
"""

from __future__ import annotations

import cv2
import numpy as np

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.vision.frame_key import frame_bytes
from mobigrasp.host.vision.grey import grey_cost, to_grey

THRESH_NUM, THRESH_DEN = 45, 100  # dark threshold as a fraction of the bright level
THRESH_MIN, THRESH_MAX = 40, 130
BRIGHT_FRACTION_DEN = 500  # bright level: the grey level of the brightest 0.2 % of pixels
CLIP_MEDIAN_NUM = 65  # bright level clipped: the threshold at least this share (/100) of the median


def check_rgb(rgb: np.ndarray, who: str) -> None:
    """ValueError naming the problem unless ``rgb`` is a non-empty (H, W, 3) uint8 array."""
    if not isinstance(rgb, np.ndarray):
        raise ValueError(f"{who}: expected a numpy array, got {type(rgb).__name__}")
    if rgb.dtype != np.uint8:
        raise ValueError(f"{who}: expected dtype uint8, got {rgb.dtype}")
    if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.shape[0] < 16 or rgb.shape[1] < 16:
        raise ValueError(f"{who}: expected shape (H, W, 3) with H, W >= 16, got {rgb.shape}")


def dark_mask(grey: np.ndarray) -> tuple[np.ndarray, int, OpCounts]:
    """(mask uint8 0/1, threshold, ops): dark = grey < threshold from the bright level."""
    n = grey.size
    # cv2.calcHist counts in float32, exact up to 2**24 pixels; twice as fast as np.bincount
    if n < 1 << 24:
        hist = cv2.calcHist([grey], [0], None, [256], [0, 256]).ravel().astype(np.int64)
    else:
        hist = np.bincount(grey.ravel(), minlength=256)
    cum = np.cumsum(hist[::-1])  # pixels at or above each level, from 255 down
    want = n // BRIGHT_FRACTION_DEN
    k = int(np.searchsorted(cum, want))
    bright = 255 - k
    t = min(THRESH_MAX, max(THRESH_MIN, bright * THRESH_NUM // THRESH_DEN))
    if k == 0 and want > 0:  # the bright level clips: the same walk goes on to the median
        median = 255 - int(np.searchsorted(cum, n // 2))
        t = max(t, median * CLIP_MEDIAN_NUM // THRESH_DEN)
    mask = (grey < t).view(np.uint8)
    return mask, t, dark_mask_cost(n)


def dark_mask_cost(n_px: int) -> OpCounts:
    """Operation counts of :func:`dark_mask` on ``n_px`` pixels (the same for any image), as
    the C loop runs (hostc/dark.c, docs/budget.md): the histogram pass reads a pixel, loads,
    increments and stores its bin and counts the loop (11 cycles), the mask pass reads,
    compares, stores and counts (10); both passes fetch the grey image from SDRAM (76.8 kB at
    320x240 does not stay in the 16 KB D-cache); the level search walks at most 256 bins (to
    the bright level, and in a clipped frame on to the median)."""
    n = int(n_px)
    return OpCounts(pixels_read=2 * n, pixels_written=2 * n, luts=n, alu=7 * n + 512,
                    branches=2 * n + 256, bytes_streamed=2 * n)


# OpenCV labels a whole frame with its thread pool, which costs more CPU than the serial
# labelling (thread start-up and merging; the host shares two cores with the simulator), and
# switching the pool size per call is dearer still (the pool is rebuilt). So the process that
# runs the host (in a one-process run, the simulator too) runs OpenCV on one thread from its
# first labelling on. Labels and stats are the same either way (host speed only).
_SINGLE_THREAD = [False]


def _serial_opencv() -> None:
    if not _SINGLE_THREAD[0]:
        cv2.setNumThreads(1)
        _SINGLE_THREAD[0] = True


# OpenCV's labelling algorithm for the 8-connected dark components: BBDT (Grana's 2x2 block
# decision table) scans the same 2x2 blocks in the same order as the default (Spaghetti), so
# it gives the same label numbers and stats (tests/test_vision_front_end_speed.py), and with
# the stats pass of OpenCV 5 it runs 20 % fewer instructions than the default and about 2/3 of
# its CPU time on the masks of paper000-exp1 (host speed only).
_CCL_8 = cv2.CCL_BBDT


def _label_cropped(mask: np.ndarray) -> tuple[int, np.ndarray, np.ndarray]:
    """``cv2.connectedComponentsWithStats`` (8-connected) of ``mask``, run only on the box of
    its non-zero pixels (OpenCV's stats pass costs per pixel; the dark print is a small part of
    most frames). The box starts on even rows and columns so OpenCV's 2x2 block scan meets the
    print as in the whole frame: the same label numbers. Stats of the background (label 0) are
    those of the whole frame."""
    H, W = mask.shape
    bx, by, bw, bh = cv2.boundingRect(mask)
    x0, y0 = bx & ~1, by & ~1
    x1, y1 = bx + bw, by + bh
    if bw == 0 or (x1 - x0) * (y1 - y0) * 4 > 3 * H * W:  # nothing dark, or most of the frame
        n_lab, labels, stats, _ = cv2.connectedComponentsWithStatsWithAlgorithm(
            mask, 8, cv2.CV_32S, _CCL_8)
        return n_lab, labels, stats
    n_lab, lab, stats, _ = cv2.connectedComponentsWithStatsWithAlgorithm(
        mask[y0:y1, x0:x1], 8, cv2.CV_32S, _CCL_8)
    labels = np.zeros((H, W), np.int32)
    labels[y0:y1, x0:x1] = lab
    stats[1:, 0] += x0
    stats[1:, 1] += y0
    # background: the crop's own background (if any) and everything outside the crop; the
    # rows above/below span every column, the columns left/right every row
    xs, ys = [], []
    if stats[0, 4] > 0:
        xs += [x0 + int(stats[0, 0]), x0 + int(stats[0, 0] + stats[0, 2]) - 1]
        ys += [y0 + int(stats[0, 1]), y0 + int(stats[0, 1] + stats[0, 3]) - 1]
    if y0 > 0 or y1 < H:
        xs += [0, W - 1]
        ys += [0 if y0 > 0 else y1, H - 1 if y1 < H else y0 - 1]
    if x0 > 0 or x1 < W:
        ys += [0, H - 1]
        xs += [0 if x0 > 0 else x1, W - 1 if x1 < W else x0 - 1]
    stats[0, 0], stats[0, 1] = min(xs), min(ys)
    stats[0, 2], stats[0, 3] = max(xs) - min(xs) + 1, max(ys) - min(ys) + 1
    stats[0, 4] = H * W - int(stats[1:, 4].sum())
    return n_lab, labels, stats


def components(mask: np.ndarray) -> tuple[int, np.ndarray, np.ndarray, OpCounts]:
    """8-connected components of a 0/1 mask: (count, labels int32, stats int32, ops).

    Charged as the two-pass block labelling with the stats accumulation (:func:`components_cost`).
    """
    n = mask.size
    _serial_opencv()
    n_lab, labels, stats = _label_cropped(mask)
    return int(n_lab), labels, stats, components_cost(n)


def components_cost(n_px: int) -> OpCounts:
    """Operation counts of :func:`components` on a mask of ``n_px`` pixels, as the C labelling
    runs (hostc/label.c, docs/budget.md): the 2x2 block pass reads the mask once, the label
    pass reads it again and, for every pixel, the background included, loads and updates its
    label's five stats (about 6 table loads, 4 stores, 14 ALU operations and 2 loop branches
    per pixel); the mask is fetched from SDRAM twice. A dark pixel adds about 37 cycles of
    union-find and parent look-up that a size-only count leaves out (the median frame has few)."""
    n = int(n_px)
    return OpCounts(pixels_read=2 * n, pixels_written=4 * n, luts=6 * n, alu=14 * n,
                    branches=2 * n, bytes_streamed=2 * n)



def dark_components(rgb: np.ndarray, who: str
                    ) -> tuple[np.ndarray, np.ndarray, int, np.ndarray, np.ndarray, OpCounts]:
    """The front end the 000 detectors share: check, grey, dark mask, 8-connected components.

    Returns ``(grey, mask, n_labels, labels, stats, ops)`` with the ops of all three stages.
    """
    check_rgb(rgb, who)
    key = frame_bytes(rgb)
    last = _LAST_FRONT_END[0]
    if last is not None and last[0] == rgb.shape and last[1] == key:
        grey, mask, n_lab, labels, stats, ops = last[2]
        return grey, mask, n_lab, labels, stats, OpCounts(*ops.as_tuple())
    grey, ops = to_grey(rgb)
    mask, _, o = dark_mask(grey)
    ops += o
    n_lab, labels, stats, o = components(mask)
    ops += o
    for a in (grey, mask, labels, stats):
        a.flags.writeable = False  # shared by the detectors of one frame: nobody may write
    _LAST_FRONT_END[0] = (rgb.shape, key, (grey, mask, n_lab, labels, stats, ops))
    return grey, mask, n_lab, labels, stats, OpCounts(*ops.as_tuple())


def front_end_min_ops(height: int, width: int) -> OpCounts:
    """What :func:`dark_components` charges for any ``height x width`` frame it accepts: grey,
    dark mask and labelling all cost per pixel, whatever the frame shows (tests check equality).
    The 000 detectors only add to it, so it is a lower bound of their cost (host/app.py uses
    it to know a vision job cannot have ended yet)."""
    n = int(height) * int(width)
    return grey_cost(height, width) + dark_mask_cost(n) + components_cost(n)


# The front end of the last frame seen, keyed by the frame's bytes: in ADJUST and LIFT the dual
# "+" and the radial symbol run on the same frame and would both compute it. Host speed only:
# each detector's counts include the whole front end; HostApp charges it once a frame (the
# ``front_end`` of host/vision/registry.py).
_LAST_FRONT_END: list = [None]


def forget_front_end() -> None:
    """The next :func:`dark_components` computes its front end again, whatever frame it gets
    (for a caller that changed the thresholds the cached front end was made with)."""
    _LAST_FRONT_END[0] = None


def edge_q4(line: np.ndarray, i_dark: int, step: int) -> int | None:
    """Sub-pixel position (Q4 px, along ``line``) of the light-to-dark edge ending at ``i_dark``.

    ``step`` is -1 when the light side is at lower indices, +1 when it is at higher ones. The
    edge is where the grey level crosses the middle of the local light and dark levels, by
    linear interpolation between the two pixels that straddle it (exact for a box-filtered
    step edge). None if no straddling pair is found within 3 px.
    """
    n = len(line)
    # every pixel read below lies within 4 of i_dark: one slice to plain ints (host speed)
    w0 = max(0, i_dark - 4)
    seg = line[w0:max(w0, min(n, i_dark + 5))]
    g = seg.tolist() if isinstance(seg, np.ndarray) else [int(v) for v in seg]
    lo_i = [i_dark + k * -step for k in range(0, 3) if 0 <= i_dark + k * -step < n]
    hi_i = [i_dark + k * step for k in range(1, 4) if 0 <= i_dark + k * step < n]
    if not lo_i or not hi_i:
        return None
    g_dark = min(g[i - w0] for i in lo_i)
    g_light = max(g[i - w0] for i in hi_i)
    mid2 = g_dark + g_light  # twice the mid level: compare 2 g against it, no division
    if g_light - g_dark < 8:
        return None
    # walk outwards from two pixels inside the dark side: the first crossing is this edge (the
    # mid-level crossing can lie just inside the first dark pixel when it is partly covered);
    # further out on the light side there may be other print (the inner ring)
    for k in range(-2, 4):
        a, b = i_dark + (k + 1) * step, i_dark + k * step  # a lighter side, b one step darker
        if not (0 <= a < n and 0 <= b < n):
            continue
        ga2, gb2 = 2 * g[a - w0], 2 * g[b - w0]
        if ga2 >= mid2 > gb2:
            frac_q4 = (16 * (ga2 - mid2)) // (ga2 - gb2)  # 0..15 from a towards b
            return 16 * a - step * frac_q4
    return None


EDGE_OPS = OpCounts(pixels_read=14, alu=30, branches=10, divs=1)


def nonzero_yx(sel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.nonzero`` of a 2-D array, (rows, columns) as int64 in C order: from the flat
    indices (numpy's 2-D nonzero steps a multi-index iterator per element, ~5x dearer)."""
    return np.divmod(np.flatnonzero(sel), sel.shape[1])


def moments(sel: np.ndarray, x0: int, y0: int) -> tuple[int, int, int, int, int, int]:
    """Integer moments of a bool ROI at (x0, y0): (m00, m10, m01, m20, m11, m02) in px units."""
    ys, xs = nonzero_yx(sel)
    xs += x0
    ys += y0
    return (len(xs), int(xs.sum()), int(ys.sum()), int((xs * xs).sum()), int((xs * ys).sum()),
            int((ys * ys).sum()))


def moments_ops(roi_px: int, hits: int) -> OpCounts:
    """Cost of :func:`moments`: read the ROI, 3 MUL and 5 adds per hit."""
    return OpCounts(pixels_read=roi_px, alu=roi_px + 5 * hits, branches=roi_px // 4,
                    muls32=3 * hits)
