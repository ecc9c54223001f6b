"""The C kernels of ``hostc/`` built with the host's C compiler through cffi, as numpy calls.

The module's declarations are ``kernels.h`` itself, and it is kept in the cache of the C parts
(src/mobigrasp/cbuild.py: ``$MOBIGRASP_CACHE_DIR``, default ``~/.cache/mobigrasp``,
``hostc/<hash>``), so it is made once per change of the C. Each wrapper
takes and returns the arrays of its Python counterpart in host/vision/.
"""

from __future__ import annotations

import hashlib
from functools import lru_cache
from pathlib import Path

import numpy as np

from mobigrasp import cbuild
from mobigrasp.host.planning.clearance_q import CLEAR_WORDS
from mobigrasp.resources import data_dir

HOSTC = data_dir("mobigrasp.hostc_sources")
SOURCES = ("grey.c", "dark.c", "label.c", "edge.c", "radial_symbol.c",
           "red_cylinder.c", "trig.c", "dual_plus.c", "spoke.c", "ranging.c", "double_cross.c",
           "bezier.c", "bezier000.c", "bezier001.c", "clearance.c", "budget.c")


def source_hash() -> str:
    """Hash of the C sources and headers (the cache key of both builds)."""
    h = hashlib.sha256()
    for name in (*sorted(p.name for p in HOSTC.glob("*.h")), *SOURCES):
        h.update(name.encode() + b"\0" + (HOSTC / name).read_bytes())
    h.update(Path(cbuild.__file__).read_bytes())
    return h.hexdigest()[:16]


def cache_dir() -> Path:
    """Where the calibration's builds and results are kept (the cache of the C parts)."""
    return cbuild.cache_root()


class HostcBuildError(RuntimeError):
    """The host kernels could not be compiled or loaded on this machine."""


@lru_cache(maxsize=1)
def lib():
    """The compiled module's ``(ffi, lib)``, built on first use."""
    digest = source_hash()
    name = f"_mg_hostc_{digest}"
    target = cbuild.cache_root() / "hostc" / digest
    return cbuild.cffi_library(name, target, ("kernels.h",), [HOSTC / s for s in SOURCES],
                               [HOSTC], HostcBuildError)


def _ptr(ffi, a: np.ndarray, ctype: str):
    return ffi.cast(ctype, ffi.from_buffer(a))


def grey(rgb: np.ndarray) -> np.ndarray:
    """(H, W) uint8 grey of an (H, W, 3) uint8 frame."""
    ffi, c = lib()
    rgb = np.ascontiguousarray(rgb)
    out = np.empty(rgb.shape[:2], np.uint8)
    c.mg_grey(_ptr(ffi, rgb, "uint8_t *"), _ptr(ffi, out, "uint8_t *"), out.size)
    return out


def dark_mask(grey_img: np.ndarray) -> tuple[np.ndarray, int]:
    """(mask 0/1 uint8, threshold) of a grey image."""
    ffi, c = lib()
    g = np.ascontiguousarray(grey_img)
    mask = np.empty_like(g)
    hist = np.empty(256, np.uint32)
    t = c.mg_dark_mask(_ptr(ffi, g, "uint8_t *"), _ptr(ffi, mask, "uint8_t *"), g.size,
                       _ptr(ffi, hist, "uint32_t *"))
    return mask, int(t)


def label_scratch_words(h: int, w: int) -> tuple[int, int]:
    """Words of the block-label and parent scratch buffers of :func:`label` (stats: 5 per
    parent entry)."""
    blocks = ((w + 1) // 2) * ((h + 1) // 2)
    return blocks, blocks + 1


def label(mask: np.ndarray) -> tuple[int, np.ndarray, np.ndarray]:
    """(n_labels, labels int32, stats int32 (n, 5)) of a 0/1 mask, 8-connected."""
    ffi, c = lib()
    m = np.ascontiguousarray(mask)
    h, w = m.shape
    nb, npar = label_scratch_words(h, w)
    labels = np.empty((h, w), np.int32)
    block_lab = np.empty(nb, np.int32)
    parent = np.empty(npar, np.int32)
    stats = np.empty((npar, 5), np.int32)
    n = c.mg_label(_ptr(ffi, m, "uint8_t *"), w, h, _ptr(ffi, labels, "int32_t *"),
                   _ptr(ffi, block_lab, "int32_t *"), _ptr(ffi, parent, "int32_t *"),
                   _ptr(ffi, stats, "int32_t *"))
    return int(n), labels, stats[:n].copy()


def edge_q4(line: np.ndarray, i_dark: int, step: int) -> int | None:
    """The C ``mg_edge_q4`` on a 1-D uint8 line (None when there is no edge)."""
    ffi, c = lib()
    ln = np.ascontiguousarray(line, np.uint8)
    out = ffi.new("int32_t *")
    ok = c.mg_edge_q4(_ptr(ffi, ln, "uint8_t *"), 1, len(ln), int(i_dark), int(step), out)
    return int(out[0]) if ok else None


def radial_symbol(grey_img: np.ndarray, stats: np.ndarray, f_px: int = 611, u0_px: int = 160,
                  v0_px: int = 120) -> tuple[int, ...] | None:
    """(u_q4, v_q4, diameter_q4, y_oc_mm, x_oc_mm, z_oc_mm) of the radial symbol, from the
    front end's grey image and component stats, or None."""
    return radial_symbol_counted(grey_img, stats, f_px, u0_px, v0_px)[0]


def radial_symbol_counted(grey_img: np.ndarray, stats: np.ndarray, f_px: int = 611,
                          u0_px: int = 160, v0_px: int = 120
                          ) -> tuple[tuple[int, ...] | None, tuple[int, ...]]:
    """:func:`radial_symbol` and the operation counts it charged (:func:`ops_tuple`), the
    front end's apart."""
    ffi, c = lib()
    g = np.ascontiguousarray(grey_img)
    h, w = g.shape
    st = np.ascontiguousarray(stats, np.int32)
    scratch = np.empty(c.mg_radial_scratch_bytes(w, h) // 4 + 1, np.int32)
    out = np.zeros(6, np.int32)
    ops = ffi.new("mg_ops_t *")
    found = c.mg_radial_symbol(_ptr(ffi, g, "uint8_t *"), w, h, _ptr(ffi, st, "int32_t *"),
                               len(st), f_px, u0_px, v0_px, _ptr(ffi, scratch, "uint8_t *"),
                               _ptr(ffi, out, "int32_t *"), ops)
    return (tuple(int(v) for v in out) if found else None), ops_tuple(ops)


def detect_radial_symbol(rgb: np.ndarray, f_px: int = 611, u0_px: int = 160,
                         v0_px: int = 120) -> tuple[int, ...] | None:
    """The whole detector in C: grey, dark mask, labelling, radial symbol."""
    return detect_radial_symbol_counted(rgb, f_px, u0_px, v0_px)[0]


def front_end_ops(h: int, w: int) -> tuple[int, ...]:
    """What the C front end of the 000 detectors (grey, dark mask, labelling) charges on an
    h x w frame (:func:`ops_tuple`)."""
    ffi, c = lib()
    o = ffi.new("mg_ops_t *")
    c.mg_grey_ops(o, h, w)
    c.mg_dark_mask_ops(o, h * w)
    c.mg_components_ops(o, h * w)
    return ops_tuple(o)


def detect_radial_symbol_counted(rgb: np.ndarray, f_px: int = 611, u0_px: int = 160,
                                 v0_px: int = 120
                                 ) -> tuple[tuple[int, ...] | None, tuple[int, ...]]:
    """:func:`detect_radial_symbol` and the operation counts it charged, the front end's
    included, as host/vision/radial_symbol.py charges them."""
    return _with_front_end(rgb, lambda g, _labels, stats: radial_symbol_counted(
        g, stats, f_px, u0_px, v0_px))


def _with_front_end(rgb: np.ndarray, kernel, *args) -> tuple:
    """``kernel(grey, labels, stats, *args)`` after the C front end (grey, dark mask,
    labelling): its result and its counts with the front end's added, as the Python 000
    detectors charge them."""
    g = grey(rgb)
    m, _ = dark_mask(g)
    _, labels, stats = label(m)
    res, ops = kernel(g, labels, stats, *args)
    fe = front_end_ops(rgb.shape[0], rgb.shape[1])
    return res, tuple(a + b for a, b in zip(ops, fe, strict=True))


def ops_tuple(ops) -> tuple[int, ...]:
    """A C ``mg_ops_t`` as host.budget.OpCounts.as_tuple() gives its counts."""
    return (ops.pixels_read, ops.pixels_written, ops.alu, ops.branches, ops.muls, ops.muls32,
            ops.divs, ops.luts, ops.float_ops, ops.float_divs, ops.bytes_streamed)


def _rgb_kernel(name: str, rgb: np.ndarray, n_out: int) -> tuple[int, ...] | None:
    """Call the red detector ``name`` (frame, size, the red scratch, ``n_out`` out words)."""
    return _rgb_kernel_counted(name, rgb, n_out)[0]


def _rgb_kernel_counted(name: str, rgb: np.ndarray, n_out: int
                        ) -> tuple[tuple[int, ...] | None, tuple[int, ...]]:
    """:func:`_rgb_kernel` and the operation counts it charged (:func:`ops_tuple`)."""
    ffi, c = lib()
    img = np.ascontiguousarray(rgb)
    h, w = img.shape[:2]
    scratch = np.empty(c.mg_red_scratch_bytes(w, h) // 4 + 1, np.int32)
    out = np.zeros(n_out, np.int32)
    ops = ffi.new("mg_ops_t *")
    found = getattr(c, name)(_ptr(ffi, img, "uint8_t *"), w, h, _ptr(ffi, scratch, "uint8_t *"),
                             _ptr(ffi, out, "int32_t *"), ops)
    return (tuple(int(v) for v in out) if found else None), ops_tuple(ops)


def detect_red_cylinder(rgb: np.ndarray) -> tuple[int, ...] | None:
    """(u_c_q4, v_c_q4, ring1_v_q4, ring2_v_q4, d_pixel_q4, width_q4, x, y, w, h) of the 002
    red cylinder in C, or None."""
    return _rgb_kernel("mg_red_cylinder", rgb, 10)


def detect_red_cylinder_counted(rgb: np.ndarray
                                ) -> tuple[tuple[int, ...] | None, tuple[int, ...]]:
    """:func:`detect_red_cylinder` and the operation counts it charged (:func:`ops_tuple`)."""
    return _rgb_kernel_counted("mg_red_cylinder", rgb, 10)


def detect_red_roi_counted(rgb: np.ndarray) -> tuple[tuple[int, ...] | None, tuple[int, ...]]:
    """:func:`detect_red_roi` and the operation counts it charged (:func:`ops_tuple`)."""
    return _rgb_kernel_counted("mg_red_roi", rgb, 8)


def red_roi_tuple(res) -> tuple[int, ...]:
    """A host RedRoi as the C's out words (u_c_q4, v_c_q4, x, y, w, h, area_px, touches_edge)."""
    return (res.u_c_q4, res.v_c_q4, *res.roi, res.area_px, int(res.touches_edge))


def detect_red_roi(rgb: np.ndarray) -> tuple[int, ...] | None:
    """(u_c_q4, v_c_q4, x, y, w, h, area_px, touches_edge) of the 002 colour ROI in C, or
    None."""
    return _rgb_kernel("mg_red_roi", rgb, 8)


def sin_cos_q12(angle_mrad: int) -> tuple[int, int]:
    """The C ``mg_sin_q12`` and ``mg_cos_q12`` of an angle in mrad."""
    _, c = lib()
    return int(c.mg_sin_q12(int(angle_mrad))), int(c.mg_cos_q12(int(angle_mrad)))


def _plus_inputs(grey_img: np.ndarray, labels: np.ndarray, stats: np.ndarray):
    """The front end's arrays as the "+" kernels take them (contiguous, int32), their 8-byte
    aligned scratch (mg_dual_plus_scratch_bytes, shared by mg_spoke) and the frame's shape."""
    _, c = lib()
    g = np.ascontiguousarray(grey_img)
    h, w = g.shape
    scratch = np.empty(c.mg_dual_plus_scratch_bytes(w, h) // 8 + 1, np.int64)
    return (g, np.ascontiguousarray(labels, np.int32), np.ascontiguousarray(stats, np.int32),
            scratch, (h, w))


def dual_plus(grey_img: np.ndarray, labels: np.ndarray, stats: np.ndarray,
              alpha_mrad: int = -1571, f_px: int = 611, u0_px: int = 160
              ) -> tuple[int, ...] | None:
    """(u1_q4, v1_q4, u2_q4, v2_q4, d_pixel_q4, d_eff_q4, dist_mm, dist_raw_mm, x_oc_mm,
    y_oc_mm, z_oc_mm) of the dual "+", from the front end's grey image, labels and component
    stats, or None."""
    return dual_plus_counted(grey_img, labels, stats, alpha_mrad, f_px, u0_px)[0]


def dual_plus_counted(grey_img: np.ndarray, labels: np.ndarray, stats: np.ndarray,
                      alpha_mrad: int = -1571, f_px: int = 611, u0_px: int = 160
                      ) -> tuple[tuple[int, ...] | None, tuple[int, ...]]:
    """:func:`dual_plus` and the operation counts it charged (:func:`ops_tuple`), the front
    end's apart."""
    ffi, c = lib()
    g, lab, st, scratch, (h, w) = _plus_inputs(grey_img, labels, stats)
    out = np.zeros(11, np.int32)
    ops = ffi.new("mg_ops_t *")
    found = c.mg_dual_plus(_ptr(ffi, g, "uint8_t *"), _ptr(ffi, lab, "int32_t *"), w, h,
                           _ptr(ffi, st, "int32_t *"), len(st), int(alpha_mrad), f_px, u0_px,
                           _ptr(ffi, scratch, "uint8_t *"), _ptr(ffi, out, "int32_t *"), ops)
    return (tuple(int(v) for v in out) if found else None), ops_tuple(ops)


def detect_dual_plus(rgb: np.ndarray, alpha_mrad: int = -1571, f_px: int = 611,
                     u0_px: int = 160) -> tuple[int, ...] | None:
    """The whole detector in C: grey, dark mask, labelling, dual "+"."""
    return detect_dual_plus_counted(rgb, alpha_mrad, f_px, u0_px)[0]


def detect_dual_plus_counted(rgb: np.ndarray, alpha_mrad: int = -1571, f_px: int = 611,
                             u0_px: int = 160
                             ) -> tuple[tuple[int, ...] | None, tuple[int, ...]]:
    """:func:`detect_dual_plus` and the operation counts it charged, the front end's
    included, as host/vision/dual_plus.py charges them."""
    return _with_front_end(rgb, dual_plus_counted, alpha_mrad, f_px, u0_px)


def atan2_mrad(y: int, x: int) -> int:
    """The C ``mg_atan2_mrad``."""
    _, c = lib()
    return int(c.mg_atan2_mrad(int(y), int(x)))


def spoke_tuple(out) -> tuple:
    """A ``mg_spoke`` output as host/vision/spoke.py's Spoke fields: (u_c_q4, v_c_q4,
    points_q4, slope_q12, angle_mrad, width_q4)."""
    n = int(out[5])
    pts = tuple((int(out[6 + 2 * i]), int(out[7 + 2 * i])) for i in range(n))
    return int(out[0]), int(out[1]), pts, int(out[2]), int(out[3]), int(out[4])


def spoke(grey_img: np.ndarray, labels: np.ndarray, stats: np.ndarray) -> tuple | None:
    """The spoke of the "+" nearest the image centre (:func:`spoke_tuple`), from the front
    end's grey image, labels and component stats, or None."""
    return spoke_counted(grey_img, labels, stats)[0]


def spoke_counted(grey_img: np.ndarray, labels: np.ndarray, stats: np.ndarray
                  ) -> tuple[tuple | None, tuple[int, ...]]:
    """:func:`spoke` and the operation counts it charged (:func:`ops_tuple`), the front
    end's apart."""
    ffi, c = lib()
    g, lab, st, scratch, (h, w) = _plus_inputs(grey_img, labels, stats)
    out = np.zeros(26, np.int32)
    ops = ffi.new("mg_ops_t *")
    found = c.mg_spoke(_ptr(ffi, g, "uint8_t *"), _ptr(ffi, lab, "int32_t *"), w, h,
                       _ptr(ffi, st, "int32_t *"), len(st), _ptr(ffi, scratch, "uint8_t *"),
                       _ptr(ffi, out, "int32_t *"), ops)
    return (spoke_tuple(out) if found else None), ops_tuple(ops)


def detect_spoke(rgb: np.ndarray) -> tuple | None:
    """The whole detector in C: grey, dark mask, labelling, spoke."""
    return detect_spoke_counted(rgb)[0]


def detect_spoke_counted(rgb: np.ndarray) -> tuple[tuple | None, tuple[int, ...]]:
    """:func:`detect_spoke` and the operation counts it charged, the front end's included, as
    host/vision/spoke.py charges them."""
    return _with_front_end(rgb, spoke_counted)


def locate_ring_pair(d_pixel_q4: int, u_q4: int, v_q4: int, width_q4: int, alpha_mrad: int,
                     theta5_mrad: int, f_px: int = 350, u0_px: int = 160, v0_px: int = 120,
                     d_um: int = 14_500) -> tuple[int, ...] | None:
    """The C ``mg_locate_ring_pair``: host/ranging.py RingPairFix's fields (x_mm, y_mm, z_mm,
    dist_mm, bearing_mrad, radius_mm), or None outside the C's range (hostc/kernels.h)."""
    ffi, c = lib()
    out = np.zeros(6, np.int32)
    ok = c.mg_locate_ring_pair(int(d_pixel_q4), int(u_q4), int(v_q4), int(width_q4),
                               int(alpha_mrad), int(theta5_mrad), int(f_px), int(u0_px),
                               int(v0_px), int(d_um), _ptr(ffi, out, "int32_t *"))
    return tuple(int(v) for v in out) if ok else None


def _i32(a) -> np.ndarray:
    return np.ascontiguousarray(a, np.int32)


def _i64(a) -> np.ndarray:
    return np.ascontiguousarray(a, np.int64)


def bezier000(ctrl_q: np.ndarray, n: int, lim: np.ndarray, k1_q16: int, k2_q16: int
              ) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    """The C ``mg_bezier000``: (best index or -1, reasons, first violated samples, Q16 costs)."""
    ffi, c = lib()
    ctrl, lim = _i32(ctrl_q), _i32(lim)
    m = ctrl.shape[0]
    reason, first, cost = np.zeros(m, np.int32), np.zeros(m, np.int32), np.zeros(m, np.int64)
    best = c.mg_bezier000(_ptr(ffi, ctrl, "int32_t *"), m, int(n), _ptr(ffi, lim, "int32_t *"),
                          int(k1_q16), int(k2_q16), _ptr(ffi, reason, "int32_t *"),
                          _ptr(ffi, first, "int32_t *"), _ptr(ffi, cost, "int64_t *"))
    return int(best), reason, first, cost


def bezier001_coarse(ctrl_q: np.ndarray, n: int, lim: np.ndarray, geo: np.ndarray, n_reg: int,
                     per_sample_cycles: int, setup_cycles: int, cut_cycles: int, k1_q16: int,
                     k2_q16: int) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    """The C ``mg_bezier001_coarse``: (curves taken, reasons, first violated samples, costs)."""
    ffi, c = lib()
    ctrl, lim, geo = _i32(ctrl_q), _i32(lim), _i64(geo)
    m = ctrl.shape[0]
    reason, first, cost = np.zeros(m, np.int32), np.zeros(m, np.int32), np.zeros(m, np.int64)
    taken = c.mg_bezier001_coarse(
        _ptr(ffi, ctrl, "int32_t *"), m, int(n), _ptr(ffi, lim, "int32_t *"),
        _ptr(ffi, geo, "int64_t *"), int(n_reg), int(per_sample_cycles), int(setup_cycles),
        int(cut_cycles), int(k1_q16), int(k2_q16), _ptr(ffi, reason, "int32_t *"),
        _ptr(ffi, first, "int32_t *"), _ptr(ffi, cost, "int64_t *"))
    return int(taken), reason, first, cost


def path_clearance(words: np.ndarray, x_q4: np.ndarray, y_q4: np.ndarray) -> int:
    """The C ``mg_path_clearance``: D_m (1/16 mm) of one path's samples to the regions."""
    ffi, c = lib()
    w = _i64(np.asarray(words).reshape(-1))
    x, y = _i64(x_q4), _i64(y_q4)
    return int(c.mg_path_clearance(_ptr(ffi, w, "int64_t *"), len(w) // CLEAR_WORDS,
                                   _ptr(ffi, x, "int64_t *"), _ptr(ffi, y, "int64_t *"),
                                   int(x.size)))


def bezier001_fine(ctrl_q: np.ndarray, n: int, lim: np.ndarray, geo: np.ndarray, n_reg: int,
                   per_sample_cycles: int, setup_cycles: int, worst_us: int, budget_us: int
                   ) -> tuple[int, np.ndarray]:
    """The C ``mg_bezier001_fine``: (index of the first that passes or -1, reasons of those
    tried)."""
    ffi, c = lib()
    ctrl, lim, geo = _i32(ctrl_q), _i32(lim), _i64(geo)
    m = ctrl.shape[0]
    reason, tried = np.zeros(max(1, m), np.int32), ffi.new("int32_t *")
    got = c.mg_bezier001_fine(_ptr(ffi, ctrl, "int32_t *"), m, int(n),
                              _ptr(ffi, lim, "int32_t *"), _ptr(ffi, geo, "int64_t *"),
                              int(n_reg), int(per_sample_cycles), int(setup_cycles),
                              int(worst_us), int(budget_us), _ptr(ffi, reason, "int32_t *"),
                              tried)
    return int(got), reason[:int(tried[0])].copy()


def double_cross_tuple(out) -> tuple:
    """A ``mg_double_cross`` output as host/vision/double_cross.py's DoubleCrossResult fields:
    (u1_q4, v1_q4, u2_q4, v2_q4, um_q4, vm_q4, d_pixel_q4, e_mrad, (votes1, votes2))."""
    return (*(int(v) for v in out[:8]), (int(out[8]), int(out[9])))


def double_cross(grey_img: np.ndarray, yaw_mrad: int = 0, pitch_mrad: int = 0,
                 f_px: int = 350) -> tuple | None:
    """The 002 double cross (:func:`double_cross_tuple`) from a grey image, or None."""
    return double_cross_counted(grey_img, yaw_mrad, pitch_mrad, f_px)[0]


def double_cross_counted(grey_img: np.ndarray, yaw_mrad: int = 0, pitch_mrad: int = 0,
                         f_px: int = 350) -> tuple[tuple | None, tuple[int, ...]]:
    """:func:`double_cross` and the operation counts it charged (:func:`ops_tuple`), the grey
    image's apart."""
    ffi, c = lib()
    g = np.ascontiguousarray(grey_img, np.uint8)
    h, w = g.shape
    scratch = np.empty(c.mg_double_cross_scratch_bytes(w, h) // 8 + 1, np.int64)
    out = np.zeros(10, np.int32)
    ops = ffi.new("mg_ops_t *")
    found = c.mg_double_cross(_ptr(ffi, g, "uint8_t *"), w, h, int(yaw_mrad), int(pitch_mrad),
                              int(f_px), _ptr(ffi, scratch, "uint8_t *"),
                              _ptr(ffi, out, "int32_t *"), ops)
    return (double_cross_tuple(out) if found else None), ops_tuple(ops)


def detect_double_cross(rgb: np.ndarray, yaw_mrad: int = 0, pitch_mrad: int = 0,
                        f_px: int = 350) -> tuple | None:
    """The whole detector in C: grey, double cross."""
    return double_cross(grey(rgb), yaw_mrad, pitch_mrad, f_px)


def detect_double_cross_counted(rgb: np.ndarray, yaw_mrad: int = 0, pitch_mrad: int = 0,
                                f_px: int = 350) -> tuple[tuple | None, tuple[int, ...]]:
    """:func:`detect_double_cross` and the operation counts it charged, the grey image's
    included (mg_grey_ops), as host/vision/double_cross.py charges them."""
    ffi, c = lib()
    res, ops = double_cross_counted(grey(rgb), yaw_mrad, pitch_mrad, f_px)
    g = ffi.new("mg_ops_t *")
    c.mg_grey_ops(g, rgb.shape[0], rgb.shape[1])
    return res, tuple(a + b for a, b in zip(ops, ops_tuple(g), strict=True))
