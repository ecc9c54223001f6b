"""Double-cross approach-guidance marker of paper 002 (§2.1), integer only.

The marker is two crosses side by side; each cross has a dark centre and four dark spokes of
equal width separated by equal gaps. The four steps of 002 §2.1:

1. **Ω_p1** — candidate centres: a pixel p_c is kept when it is dark and the ring around it is
   centrally symmetric with both dark and light parts. We test this with the max and the min of
   the grey level over an 8-point ring (one integer dilate and one erode with a ring kernel):
   ``max_ring >= g(p_c) + T_h`` (light gaps exist), ``min_ring < g(p_c) + T_h`` (dark spokes
   exist) and ``2 g(p_c) <= max_ring + min_ring`` (the centre is on the dark side).
2. **Binarised ring template** — ``G_pc(i) = 0 if g(x_i) < g(p_c) + T_h else 1`` over ``n``
   ring points (002 eq. in step 2; T_h = 30).
3. **Ω_p2** — keep p_c whose 0/1 pattern has exactly 4 dark runs (4 spokes) and is within
   ``RING_HAMMING`` points of an ideal ring of 4 equal spokes and 4 equal gaps, and the gaps
   on average at least 2 T_h brighter than the spokes and than p_c (contrast of a printed
   marker, not of the floor).
4. **Two groups** — Ω_p2 points are grouped by pixel coordinates (connected cells of a coarse
   grid) on each pyramid level; the pair of groups of one level with the most votes (and a
   plausible spacing) are the crosses, their means are (u1, v1) and (u2, v2).

Paper 002 §5 gives n = 10 for the template (its Fig. 2(b), the template drawing, is not in
our copy, so whether n counts points or sets the radius is not known); 10 points cannot show
four equal spokes and four equal gaps at every turn of the cross. Our ring has 24 points (a
quarter turn is then 6 samples, so "equal width and equal gap" is a match against 24 ideal
rings) and we run the same ring of radius 6 px on a 3-level 2x2-mean pyramid so one
template covers crosses from about 7 to 80 px radius (0.2-2.5 m for the 50 mm crosses at
f = 350). This is our choice; the paper does not say how it handles scale.

The heading error e of 002 §3 (the angle between the platform heading and the line to the
marker centre, right positive like θ5 in docs/conventions.md) is computed from the pixel offset
of the marker centre and the camera's yaw and pitch (inputs, mrad). The marker centre is the
midpoint of the two cross centres weighted by their apparent heights (the nearer cross looks
bigger; at 0.3 m with the board turned 35° the plain midpoint is 1° off). It is the
bearing seen from the camera; 002 measures e from the platform, which differs by the arm's
parallax (the camera is ~0.2 m ahead of the waist): with a range,
``mobigrasp.host.ranging.platform_bearing_mrad`` converts it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from mobigrasp.host import fixedpoint as fp
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.vision.dark_blobs import components_cost
from mobigrasp.host.vision.grey import grey_cost, noise_sigma, to_grey

T_H = 30  # 002 §5: binarisation threshold above g(p_c)
RING_N = 24  # template points on the ring (002 uses n = 10, see module docstring)
RING_R_PX = 6  # ring radius at every pyramid level
LEVELS = 3  # pyramid levels 0 (320x240), 1 (160x120), 2 (80x60)
RING_HAMMING = 4  # template points allowed to differ from an ideal 4-spoke ring
MIN_VOTES = 1  # Ω_p2 points a cross needs
STOP_VOTES = 3  # a pair with this many votes each ends the coarse-to-fine search

F_PX_002 = 350
U0_PX = 160
V0_PX = 120


def _ring_offsets(radius: int, n: int) -> tuple[tuple[int, int], ...]:
    # Configuration-time table (a const array on the board).
    return tuple((round(radius * math.cos(2 * math.pi * k / n)),
                  round(radius * math.sin(2 * math.pi * k / n))) for k in range(n))


_RING = _ring_offsets(RING_R_PX, RING_N)
_RING8 = _ring_offsets(RING_R_PX, 8)
_KERNEL8 = np.zeros((2 * RING_R_PX + 1, 2 * RING_R_PX + 1), np.uint8)
for _dx, _dy in _RING8:
    _KERNEL8[_dy + RING_R_PX, _dx + RING_R_PX] = 1


@dataclass(frozen=True)
class DoubleCrossResult:
    """Both cross centres (left one first in the image), the marker centre, spacing and e.

    Pixel coordinates and lengths are Q4 (1/16 px); (um, vm) is the marker centre (midpoint of
    the cross centres weighted by apparent size, see the module docstring); ``e_mrad`` is its
    bearing from the platform heading, right positive; ``votes`` are the Ω_p2 counts.
    """

    u1_q4: int
    v1_q4: int
    u2_q4: int
    v2_q4: int
    um_q4: int
    vm_q4: int
    d_pixel_q4: int
    e_mrad: int
    votes: tuple[int, int]


class _Tally(dict):
    """Operation counts summed by name, one OpCounts at the end (``OpCounts(**tally)``):
    OpCounts.__add__ builds an object per addition and Counter.update checks for a Mapping
    through the abc machinery on every call; plain dict adds are several times cheaper."""

    def add(self, counts: dict | None = None, **kw: int) -> None:
        for src in (counts or {}, kw):
            for k, v in src.items():
                self[k] = self.get(k, 0) + v


def _downsample(g: np.ndarray) -> np.ndarray:
    """One pyramid level: the rounded mean ``(a + b + c + d + 2) >> 2`` of each 2x2 block (an
    odd last row or column is dropped). OpenCV's area resize by exactly 1/2 computes this
    integer formula for uint8 (tests/test_vision_host_speed.py compares it with the numpy
    sums), several times faster than four strided numpy adds."""
    h, w = (g.shape[0] // 2) * 2, (g.shape[1] // 2) * 2
    return cv2.resize(g[:h, :w], (w // 2, h // 2), interpolation=cv2.INTER_AREA)


def _downsample_ops(out_pixels: int) -> OpCounts:
    # The counts of this module follow hostc/double_cross.c as ARM920T code (docs/budget.md):
    # per output pixel four byte loads, the sum, a store and the loop branch (~19 cycles), the
    # level read from SDRAM once.
    n = int(out_pixels)
    return OpCounts(pixels_read=4 * n, pixels_written=n, alu=7 * n, branches=n,
                    bytes_streamed=4 * n)


def _noise_ops(height: int, width: int) -> OpCounts:
    """:func:`noise_sigma` as the C runs it: per difference two byte loads, the absolute value,
    a histogram word loaded, incremented and stored and the loop branch (~13 cycles); the rows
    read from SDRAM; the histogram cleared and walked."""
    if width < 2:
        return OpCounts()
    rows = -(-int(height) // 4)
    n = rows * (int(width) - 1)
    return OpCounts(pixels_read=2 * n, alu=3 * n + 512, luts=n, pixels_written=n,
                    branches=n + 256, bytes_streamed=rows * int(width))


def _scan_ops(h: int, w: int) -> OpCounts:
    """The fixed part of one level's :func:`_level_candidates` in C: the grid's cells cleared
    (three words each), then per pixel at least 6 px from the border the ring max (eight byte
    loads unrolled, seven compare-and-selects), the first test and the loop (~44 cycles); the
    level read from SDRAM once."""
    cells = ((h >> 2) + 1) * ((w >> 2) + 1)
    ops = OpCounts(pixels_written=3 * cells, alu=2 * cells, branches=cells)
    r = RING_R_PX
    if h <= 2 * r or w <= 2 * r:
        return ops
    n = (h - 2 * r) * (w - 2 * r)
    return ops + OpCounts(pixels_read=9 * n, alu=20 * n, branches=2 * n, bytes_streamed=h * w)


_MASK = (1 << RING_N) - 1


def _rot(code: np.ndarray, k: int) -> np.ndarray:
    """Rotate RING_N-bit ring codes by k samples (a barrel shift on the ARM)."""
    return ((code << k) | (code >> (RING_N - k))) & _MASK


_BIT_WEIGHTS = np.left_shift(1, np.arange(RING_N, dtype=np.int64))  # 1, 2, 4, ... 2^(n-1)


def ring_codes(bits: np.ndarray) -> np.ndarray:
    """Pack binarised rings (k, RING_N) bool, True = light, into RING_N-bit integer words
    (bit i = point i; one exact integer matrix product, no float)."""
    return bits @ _BIT_WEIGHTS


def _templates() -> np.ndarray:
    """Ideal rings of 4 equal spokes (dark width w points) and 4 equal gaps, every phase."""
    q = RING_N // 4
    out = []
    for w in range(1, q - 1):
        quarter = [False] * w + [True] * (q - w)
        for phase in range(q):
            bits = np.array([quarter[(i + phase) % q] for i in range(RING_N)])
            out.append(int(ring_codes(bits[None])[0]))
    return np.array(out, np.int64)


def ring_pattern_ok(code: np.ndarray) -> np.ndarray:
    """Step 3 of 002 on ring words (:func:`_ring_pattern`): the Ω_p2 mask."""
    return _ring_pattern(code)[0]


def _ring_pattern(code: np.ndarray) -> tuple[np.ndarray, int]:
    """Step 3 of 002 on ring words (bit i = template point i is light): the Ω_p2 mask.

    Exactly four dark runs (popcount(code & ~rot(code, 1)) == 4 light runs start), and the word
    is within ``RING_HAMMING`` points of an ideal ring of four equal spokes and four equal gaps
    (any spoke width from 1 to RING_N/4 - 2 points, any phase): "spokes of equal width and equal
    gaps", tolerant to the anti-aliased spoke edges and to perspective. Also returns how many
    words have four dark runs (the template search's count).
    """
    ok = np.bitwise_count(code & ~_rot(code, 1) & _MASK) == 4
    # the distance to the templates only where there are four dark runs (most candidates on
    # edges and texture have fewer): the same mask, a fraction of the k x templates work
    four = code[ok]
    ok[ok] = np.bitwise_count(four[:, None] ^ _TEMPLATES[None, :]).min(axis=1, initial=RING_N) \
        <= RING_HAMMING
    return ok, int(four.size)


_TEMPLATES = _templates()


def _level_candidates(g: np.ndarray, th: int = T_H
                      ) -> tuple[np.ndarray, np.ndarray, OpCounts]:
    """Ω_p1 and Ω_p2 of one pyramid level: returns (x, y) of Ω_p2 points and the op counts."""
    h, w = g.shape
    r = RING_R_PX
    ops = _Tally(vars(_scan_ops(h, w)))
    if h <= 2 * r or w <= 2 * r:
        return np.empty(0, np.int64), np.empty(0, np.int64), OpCounts(**ops)
    mx = cv2.dilate(g, _KERNEL8, borderType=cv2.BORDER_REPLICATE)
    mn = cv2.erode(g, _KERNEL8, borderType=cv2.BORDER_REPLICATE)
    # Ω_p1 with the contrast of step 3 already applied (gap mean >= centre + 2 T_h needs
    # max >= centre + 2 T_h): cuts the candidates on the floor texture by ~10x. In saturating
    # uint8 arithmetic: max - g >= 2 T_h, min - g < T_h, g - min <= max - g (centre dark side).
    up = cv2.subtract(mx, g)
    cand = (up >= 2 * th) & (cv2.subtract(mn, g) < th) & (cv2.subtract(g, mn) <= up)
    cand[:r, :] = False
    cand[h - r:, :] = False
    cand[:, :r] = False
    cand[:, w - r:] = False
    idx = np.flatnonzero(cand)
    k = int(idx.size)
    if k == 0:
        return np.empty(0, np.int64), np.empty(0, np.int64), OpCounts(**ops)
    flat = g.astype(np.int16).ravel()
    # Step 1's central symmetry on the 8-point ring: opposite points on the same side of
    # g(p_c) + T_h in at least 2 of the 4 pairs (the others may straddle spoke edges).
    offs8 = np.array([dy * w + dx for dx, dy in _RING8], np.int64)
    light8 = flat[idx[:, None] + offs8[None, :]] >= (flat[idx] + th)[:, None]
    sym = np.count_nonzero(light8[:, :4] == light8[:, 4:], axis=1) >= 2
    # per Ω_p1 point in C: the eight ring values loaded again (offset table, byte, a copy kept)
    # with the min, the other two tests, the four symmetry pairs (~146 cycles)
    ops.add(luts=8 * k, pixels_read=8 * k, pixels_written=8 * k, alu=34 * k, branches=24 * k)
    idx = idx[sym]
    k = int(idx.size)
    offs = np.array([dy * w + dx for dx, dy in _RING], np.int64)
    samples = flat[idx[:, None] + offs[None, :]]
    centre = flat[idx].astype(np.int32)
    bits = samples >= (centre + th)[:, None]
    ok, n_four = _ring_pattern(ring_codes(bits))
    # per symmetric point: RING_N samples (offset table, byte, compare, bit, count and sums,
    # loop: ~19 cycles each), the run count by rotate, and-not and a 32-bit popcount; per word
    # with four dark runs the template search, up to 24 xor-popcount-compares of ~28 cycles
    # (most such words match none, so all 24 are tried)
    ops.add(luts=k * RING_N, pixels_read=k * RING_N, alu=k * (12 * RING_N + 68),
            branches=k * RING_N)
    ops.add(luts=24 * n_four, alu=563 * n_four, branches=24 * n_four)
    idx, samples, bits, centre = idx[ok], samples[ok], bits[ok], centre[ok]
    m = int(idx.size)
    # Contrast: gaps on average >= 2 T_h brighter than the spokes and than p_c (low-contrast
    # floor texture can make a 4-run pattern at T_h, never a 2 T_h one); spokes on average
    # no more than T_h darker than p_c (spokes and centre are the same ink).
    n_light = np.count_nonzero(bits, axis=1).astype(np.int32)
    n_dark = RING_N - n_light
    s_light = np.where(bits, samples, 0).sum(axis=1, dtype=np.int32)
    s_dark = np.where(bits, 0, samples).sum(axis=1, dtype=np.int32)
    ok = s_light * n_dark - s_dark * n_light >= 2 * th * n_light * n_dark
    ok &= s_light - centre * n_light >= 2 * th * n_light
    ok &= s_dark >= (centre - th) * n_dark  # spokes as dark as the centre (same ink)
    # the three tests, then the point added to its grid cell (count and two sums)
    ops.add(alu=m * (2 * RING_N + 12), muls32=4 * m, branches=2 * m, pixels_written=3 * m)
    sel = idx[ok]
    return sel % w, sel // w, OpCounts(**ops)


@dataclass(frozen=True)
class _Group:
    votes: int
    u_q4: int
    v_q4: int


def _group(xs_q4: np.ndarray, ys_q4: np.ndarray, level: int,
           shape: tuple[int, int]) -> tuple[list[_Group], OpCounts]:
    """Step 4 on one pyramid level: Ω_p2 points in 8-connected cells of 4 level pixels form a
    group; returns the groups with their mean centres (level-0 Q4), most votes first."""
    cell_shift = 4 + 2 + level  # Q4 level-0 coordinates -> cells of 4 level-l pixels
    gh, gw = (shape[0] >> (2 + level)) + 1, (shape[1] >> (2 + level)) + 1
    cx = xs_q4 >> cell_shift
    cy = ys_q4 >> cell_shift
    occ = np.zeros((gh, gw), np.uint8)
    occ[cy, cx] = 1
    nlab, lab = cv2.connectedComponents(occ, connectivity=8)
    labels = lab[cy, cx]
    cnt = np.bincount(labels, minlength=nlab)
    su = np.zeros(nlab, np.int64)
    sv = np.zeros(nlab, np.int64)
    np.add.at(su, labels, xs_q4)
    np.add.at(sv, labels, ys_q4)
    groups = [_Group(int(cnt[i]), fp.div_round(int(su[i]), int(cnt[i])),
                     fp.div_round(int(sv[i]), int(cnt[i])))
              for i in range(1, nlab) if cnt[i] >= MIN_VOTES]
    groups.sort(key=lambda g: (-g.votes, g.u_q4, g.v_q4))
    # in C: the occupied cells as a mask, labelled by hostc/label.c, then each occupied cell's
    # count and sums added to its label's (the 12-byte cells and the labels read from SDRAM);
    # a rounded division per group mean
    cells = gh * gw
    ops = components_cost(cells) + OpCounts(
        pixels_read=3 * cells, pixels_written=cells, alu=6 * cells, branches=3 * cells,
        bytes_streamed=26 * cells, divs=2 * len(groups))
    return groups, ops


def _pick_pair(groups: list[_Group], level: int) -> tuple[int, _Group, _Group] | None:
    """The two crosses on one level: the pair with the most votes standing between one ring
    diameter (two crosses cannot overlap) and 24 ring radii (beyond that the ring would be far
    smaller than the crosses, which the next level handles) apart."""
    best = None
    lo_q4 = (2 * RING_R_PX - 1) << (level + 4)
    hi_q4 = (24 * RING_R_PX) << (level + 4)
    for i in range(len(groups)):
        for j in range(i + 1, len(groups)):
            a, b = groups[i], groups[j]
            du, dv = a.u_q4 - b.u_q4, a.v_q4 - b.v_q4
            d2 = du * du + dv * dv
            if not lo_q4 * lo_q4 <= d2 <= hi_q4 * hi_q4:
                continue
            score = a.votes + b.votes
            if best is None or score > best[0]:
                best = (score, a, b)
    return best


def _vertical_extent_q4(grey: np.ndarray, u_q4: int, v_q4: int, max_px: int = 120
                        ) -> tuple[int | None, OpCounts]:
    """Apparent height of a cross (Q4 px): its vertical spokes, from the centre up and down to
    the dark/light mid-level crossings (sub-pixel). None when there is no clear crossing."""
    h, w = grey.shape
    x, y0 = (u_q4 + 8) >> 4, (v_q4 + 8) >> 4
    if not (0 <= x < w and 1 <= y0 < h - 1):
        return None, OpCounts()
    lo, hi = max(0, y0 - max_px), min(h, y0 + max_px + 1)
    col = grey[lo:hi, x].astype(np.int32)
    c = y0 - lo
    light = int(col.max())
    dark = int(col[c - 1:c + 2].min())
    ops = OpCounts(pixels_read=2 * (hi - lo), alu=3 * (hi - lo), divs=2, branches=hi - lo)
    if light - dark < 2 * T_H:
        return None, ops
    mid2 = light + dark  # compare 2 g with light + dark: integer mid-level
    total = 0
    for seg in (col[c::-1], col[c:]):  # from the centre up, and down
        over = np.flatnonzero(2 * seg >= mid2)
        if over.size == 0:
            return None, ops
        k = int(over[0])  # first row at or above mid-level; k - 1 is still dark
        if k == 0:
            return None, ops
        a, b = int(seg[k - 1]), int(seg[k])
        total += 16 * (k - 1) + fp.div_round(16 * (mid2 - 2 * a), 2 * (b - a))
    return total, ops


def bearing_mrad(u_q4: int, v_q4: int, yaw_mrad: int, pitch_mrad: int,
                 f_px: int = F_PX_002, u0_px: int = U0_PX, v0_px: int = V0_PX) -> int:
    """Horizontal bearing of pixel (u, v) from the platform heading, mrad, right positive.

    Exact for a camera with yaw θ5 (right positive) and pitch α (up positive) and no roll: the
    ray (x_n, y_n, 1) of OpenCV camera axes has forward component cos α + y_n sin α and right
    component x_n in the platform, so the bearing is θ5 + atan2(x_n, cos α + y_n sin α).
    """
    xn_q4 = u_q4 - 16 * u0_px  # x_n * f in Q4 px
    yn_q4 = v_q4 - 16 * v0_px
    s, c = fp.sincos_q12(pitch_mrad)
    fwd = c * 16 * f_px + s * yn_q4  # (cos α f + sin α y) in Q16 (Q12 x Q4)
    return int(yaw_mrad) + fp.atan2_mrad(xn_q4 * fp.ONE_Q12, fwd)


def min_ops(height: int, width: int) -> OpCounts:
    """Operation counts :func:`detect_double_cross` charges at least for any ``height x width``
    frame: grey, the pyramid, the noise estimate and the candidate scan of the coarsest level,
    which the coarse-to-fine search always runs (finer levels only when it does not stop
    there). Everything else only adds counts. A lower bound of the modelled time (host/app.py).
    """
    h, w = int(height), int(width)
    ops = grey_cost(h, w)
    for _ in range(1, LEVELS):
        h, w = h // 2, w // 2
        ops += _downsample_ops(h * w)
    ops += _noise_ops(height, width)
    return ops + _scan_ops(h, w)  # _level_candidates on the coarsest level


def detect_double_cross(rgb: np.ndarray, yaw_mrad: int = 0, pitch_mrad: int = 0,
                        f_px: int = F_PX_002) -> tuple[DoubleCrossResult | None, OpCounts]:
    """Find the 002 double cross in an RGB frame; ``(None, ops)`` when it is not there."""
    grey, g_ops = to_grey(rgb)
    ops = _Tally(vars(g_ops))
    levels = [grey]
    for _ in range(1, LEVELS):
        nxt = _downsample(levels[-1])
        ops.add(vars(_downsample_ops(nxt.size)))
        levels.append(nxt)
    # 002's T_h = 30 holds for a clean sensor; on a noisy frame the threshold follows the
    # noise (4 sigma; halved per pyramid level by the 2x2 means) so that noise cannot draw
    # spokes: a very noisy frame gives "not found", never a phantom marker.
    sigma, _ = noise_sigma(grey)
    ops.add(vars(_noise_ops(*grey.shape)))
    pair = None
    # coarse to fine; a pair seen well on a coarse level (big crosses, close by) ends the
    # search, so the many spoke-edge candidates of big crosses on level 0 are never paid for
    for lvl in range(LEVELS - 1, -1, -1):
        g = levels[lvl]
        x, y, o = _level_candidates(g, max(T_H, (4 * sigma) >> lvl))
        ops.add(vars(o))
        if x.size < 2:
            continue
        # centre of level-l pixel x in level-0 Q4: (x + 1/2) * 2^l - 1/2
        xs = ((2 * x + 1) << (lvl + 3)) - 8
        ys = ((2 * y + 1) << (lvl + 3)) - 8
        groups, o = _group(xs, ys, lvl, grey.shape)
        ops.add(vars(o))
        ops.add(alu=12 * len(groups) ** 2, muls32=2 * len(groups) ** 2)
        best = _pick_pair(groups, lvl)
        if best is not None and (pair is None or best[0] >= pair[0]):
            pair = best  # finer levels win ties: they locate the centres better
        if pair is not None and min(pair[1].votes, pair[2].votes) >= STOP_VOTES:
            break
    if pair is None:
        return None, OpCounts(**ops)
    pair = pair[1:]
    g1, g2 = sorted(pair, key=lambda g: g.u_q4)
    c1, c2 = (g1.u_q4, g1.v_q4), (g2.u_q4, g2.v_q4)
    du, dv = c2[0] - c1[0], c2[1] - c1[1]
    d_q4 = fp.isqrt(du * du + dv * dv)
    ops.add(vars(fp.isqrt_ops(du * du + dv * dv)))
    ops.add(muls32=2, alu=4)
    um, vm = (c1[0] + c2[0] + 1) >> 1, (c1[1] + c2[1] + 1) >> 1
    # perspective: the board's centre is not at the midpoint of the two image centres when one
    # cross is nearer; weight by the crosses' apparent sizes (depth ~ 1 / size)
    r1, o1 = _vertical_extent_q4(grey, c1[0], c1[1])
    r2, o2 = _vertical_extent_q4(grey, c2[0], c2[1])
    ops.add(vars(o1))
    ops.add(vars(o2))
    if r1 and r2 and 5 * r1 >= 3 * r2 and 5 * r2 >= 3 * r1:
        um = fp.div_round(r2 * c1[0] + r1 * c2[0], r1 + r2)
        vm = fp.div_round(r2 * c1[1] + r1 * c2[1], r1 + r2)
        ops.add(muls32=4, divs=2, alu=6)
    e = bearing_mrad(um, vm, yaw_mrad, pitch_mrad, f_px)
    ops.add(vars(fp.sin_ops().scaled(2)))
    ops.add(vars(fp.atan2_ops()))
    ops.add(muls32=3, alu=6)
    return DoubleCrossResult(c1[0], c1[1], c2[0], c2[1], um, vm, d_q4, e,
                             (g1.votes, g2.votes)), OpCounts(**ops)


# 002's guidance board as we built it (002 gives no sizes; docs/markers.md): cross centres 130 mm
# apart, the cylinder's axis 150 mm in front of the board's centre
CROSS_SPACING_MM_Q4 = 130 * 16
BOARD_BEHIND_MM_Q4 = 150 * 16
# the board seen at least this far off its face (the sine of the angle between its normal and
# the line of sight, Q12: 30 degrees): the cylinder is placed in the board's plane from the two
# crosses' depths (:func:`sighting`); nearer its face the frontal model (docs/task.md)
OBLIQUE_SIN_Q12 = 2048
OBLIQUE_AXIS_RATIO = 4  # ... and the cylinder placed at most atan 4 (76 degrees) off the axis
# ... and the crosses side by side: their rows differ by at most 1/4 of their columns (the board
# upright, the camera level; a pair far from level is not the board's two crosses)
OBLIQUE_LEVEL_RATIO = 4


def sighting(res: DoubleCrossResult, f_px: int) -> tuple[int, int, int] | None:
    """The cylinder in front of the board: its pixel (Q4 px) and depth along the optical axis
    (Q4 mm), the task's target (host/task/sense.py). A board seen obliquely: by
    :func:`oblique_sighting`. Else the board is taken to face the camera: the marker centre at
    the board's depth ``spacing f / d_pixel`` less BOARD_BEHIND (the board's row is used: the
    camera looks level in the approach, so the ray is nearly horizontal)."""
    if res.d_pixel_q4 <= 0:
        return None
    seen = oblique_sighting(res, f_px)
    if seen is not None:
        return seen
    return res.um_q4, res.vm_q4, CROSS_SPACING_MM_Q4 * f_px * 16 // res.d_pixel_q4 \
        - BOARD_BEHIND_MM_Q4


def oblique_sighting(res: DoubleCrossResult, f_px: int) -> tuple[int, int, int] | None:
    """The cylinder BOARD_BEHIND before the board's face along its normal, the board's plane
    found from the two crosses; None when the board is seen less than OBLIQUE_SIN_Q12 off its
    face, the pair is far from level (not the board's crosses side by side), its plane is not
    known or the place found is behind the camera or far aside.

    The marker centre ``um`` is the crosses' columns weighted by their depths (the module
    docstring), so ``(u2 - um) : (um - u1)`` is the depth ratio Z1 : Z2 of the two crosses
    (equal, with no weight: a frontal board). With x_i = (u_i - u0) / f the crosses stand at
    Z_i (x_i, 1) in the camera's level plane (x right, z along the axis), scaled so that they
    are 130 mm apart; the cylinder is their midpoint plus 150 mm along the plane's normal
    toward the camera. Seen 0.87 rad off its face, the frontal model puts the cylinder 0.2 m
    aside, at the board's post (docs/task.md)."""
    u0, f = U0_PX * 16, f_px * 16
    a, b = res.u2_q4 - res.um_q4, res.um_q4 - res.u1_q4  # Z1 : Z2
    if a <= 0 or b <= 0 or OBLIQUE_LEVEL_RATIO * abs(res.v2_q4 - res.v1_q4) > a + b:
        return None
    x1, z1 = a * (res.u1_q4 - u0), a * f  # the crosses, to one unknown scale
    x2, z2 = b * (res.u2_q4 - u0), b * f
    dx, dz = x2 - x1, z2 - z1
    span = fp.isqrt(dx * dx + dz * dz)
    if span <= 0:
        return None
    mx = CROSS_SPACING_MM_Q4 * (x1 + x2) // (2 * span)  # the board's centre, Q4 mm
    mz = CROSS_SPACING_MM_Q4 * (z1 + z2) // (2 * span)
    nx, nz = -dz * fp.ONE_Q12 // span, dx * fp.ONE_Q12 // span  # its unit normal, Q12
    if nx * mx + nz * mz > 0:
        nx, nz = -nx, -nz  # the face toward the camera
    if abs(nx * mz - nz * mx) < OBLIQUE_SIN_Q12 * fp.isqrt(mx * mx + mz * mz):
        return None
    cx = mx + BOARD_BEHIND_MM_Q4 * nx // fp.ONE_Q12
    cz = mz + BOARD_BEHIND_MM_Q4 * nz // fp.ONE_Q12
    if cz <= 0 or abs(cx) > OBLIQUE_AXIS_RATIO * cz:
        return None  # behind the camera or far aside: no usable place, the frontal model
    return u0 + f * cx // cz, res.vm_q4, cz


def detect_at_pose(rgb: np.ndarray, joints_mrad: tuple[int, ...], cam: tuple[int, int, int]
                   ) -> tuple[DoubleCrossResult | None, OpCounts]:
    """:func:`detect_double_cross` as the host calls it (host/vision/registry.py): the camera's
    yaw theta5 and pitch theta2 + theta3 + theta4 from the joint angles."""
    q = joints_mrad
    return detect_double_cross(rgb, yaw_mrad=q[5], pitch_mrad=q[2] + q[3] + q[4], f_px=cam[0])
