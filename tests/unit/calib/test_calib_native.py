"""The C kernels of hostc/ (host build) against the Python kernels, bit for bit."""

import dataclasses

import cv2
import numpy as np
import pytest
from clipped_frame import clipped_far_frame

from mobigrasp.calib import corpus, native
from mobigrasp.host import fixedpoint as fp
from mobigrasp.host import ranging
from mobigrasp.host.vision import (
    dark_blobs,
    double_cross,
    dual_plus,
    grey,
    radial_symbol,
    red_cylinder,
    spoke,
)
from mobigrasp.services.corpus import record


def _check_front_end(rgb):
    g, _ = grey.to_grey(rgb)
    assert np.array_equal(native.grey(rgb), g)
    m, t, _ = dark_blobs.dark_mask(g)
    m_c, t_c = native.dark_mask(g)
    assert t_c == t and np.array_equal(m_c, m)
    n, labels, stats, _ = dark_blobs.components(m)
    n_c, labels_c, stats_c = native.label(m)
    assert n_c == n
    assert np.array_equal(labels_c, labels)
    assert np.array_equal(stats_c, stats)


@pytest.mark.parametrize("seed", range(40))
def test_random_frames_match(seed):
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(16, 70, 2))
    rgb = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    if seed % 2:  # two-level frames: large dark components with holes and odd borders
        rgb = (rng.random((h, w, 1)) < 0.4 + 0.01 * seed).repeat(3, axis=2) * np.uint8(200) \
            + np.uint8(30)
    _check_front_end(rgb)


def test_a_clipped_frame_matches():
    """A frame whose bright level clips (camera gain 1.7): the threshold from the median level
    and the radial symbol's third local fraction, both needed to read it, the same in C."""
    rgb = clipped_far_frame()[1]
    g, _ = grey.to_grey(rgb)
    assert dark_blobs.dark_mask(g)[1] > 255 * dark_blobs.THRESH_NUM // dark_blobs.THRESH_DEN
    _check_front_end(rgb)
    res, ops = radial_symbol.detect_radial_symbol(rgb)
    assert res is not None
    assert native.detect_radial_symbol_counted(rgb) == (dataclasses.astuple(res), ops.as_tuple())


@pytest.mark.parametrize("mask", [np.ones((21, 17), np.uint8), np.zeros((21, 17), np.uint8),
                                  np.eye(19, 23, dtype=np.uint8)[::-1].copy()])
def test_edge_masks_label_as_opencv(mask):
    n, labels, stats, _ = dark_blobs.components(mask)
    n_c, labels_c, stats_c = native.label(mask)
    assert n_c == n and np.array_equal(labels_c, labels) and np.array_equal(stats_c, stats)


def _check_calls(folder, calls) -> int:
    """Compare every call of a detector ported to C; the number of results found."""
    found = 0
    for c in calls:
        rgb = corpus.load_frame(folder, {"file": c.frame_file, "sha256": _sha(folder, c)})
        if c.detector == "radial_symbol":
            res, ops = radial_symbol.detect_radial_symbol(rgb, *c.camera)
            want = None if res is None else dataclasses.astuple(res)
            got = native.detect_radial_symbol_counted(rgb, *c.camera)
            assert got == (want, ops.as_tuple()), c.frame_file  # the result and its charge
            found += want is not None
        elif c.detector == "dual_plus":
            res, ops = dual_plus.detect_at_pose(rgb, c.args[0], c.camera)
            want = None if res is None else dataclasses.astuple(res)
            q = c.args[0]
            got = native.detect_dual_plus_counted(rgb, int(q[2] + q[3] + q[4]), *c.camera[:2])
            assert got == (want, ops.as_tuple()), c.frame_file  # the result and its charge
            found += want is not None
        elif c.detector == "spoke":
            res, ops = spoke.detect_spoke(rgb)
            want = None if res is None else dataclasses.astuple(res)
            assert native.detect_spoke_counted(rgb) == (want, ops.as_tuple()), c.frame_file
            found += want is not None
        elif c.detector == "double_cross":
            res, ops = double_cross.detect_at_pose(rgb, c.args[0], c.camera)
            want = None if res is None else dataclasses.astuple(res)
            q = c.args[0]
            got = native.detect_double_cross_counted(rgb, int(q[5]), int(q[2] + q[3] + q[4]),
                                                     c.camera[0])
            assert got == (want, ops.as_tuple()), c.frame_file  # the result and its charge
            found += want is not None
        elif c.detector in ("red_cylinder", "red_roi"):
            roi, ops = red_cylinder.detect_red_roi(rgb)  # the ROI alone, on every 002 frame
            assert native.detect_red_roi_counted(rgb) == (
                None if roi is None else native.red_roi_tuple(roi), ops.as_tuple()), c.frame_file
            if c.detector == "red_roi":
                found += roi is not None
                continue
            res, ops = red_cylinder.detect_red_cylinder(rgb)
            want = None if res is None else (*dataclasses.astuple(res)[:6], *res.roi)
            assert native.detect_red_cylinder_counted(rgb) == (want, ops.as_tuple()), \
                c.frame_file
            found += want is not None
            if res is not None:  # the ranging stage that follows, over a spread of poses
                for alpha, theta5 in ((-300, 0), (-700, 420), (150, -900)):
                    fix = ranging.locate_ring_pair(res.d_pixel_q4, res.u_c_q4, res.v_c_q4,
                                                   res.width_q4, alpha, theta5)
                    got = native.locate_ring_pair(res.d_pixel_q4, res.u_c_q4, res.v_c_q4,
                                                  res.width_q4, alpha, theta5)
                    assert got == dataclasses.astuple(fix), (c.frame_file, alpha, theta5)
    return found


_SHAS: dict = {}


def _sha(folder, c):
    if folder not in _SHAS:
        _SHAS[folder] = {f["file"]: f["sha256"] for f in corpus.read_index(folder)["frames"]}
    return _SHAS[folder][c.frame_file]


def test_edge_q4_matches_on_random_lines():
    rng = np.random.default_rng(5)
    for _ in range(2000):
        line = rng.integers(0, 256, int(rng.integers(1, 12)), dtype=np.uint8)
        i, step = int(rng.integers(0, len(line))), int(rng.choice([-1, 1]))
        assert native.edge_q4(line, i, step) == dark_blobs.edge_q4(line, i, step)


def test_sin_cos_table_matches():
    for a in range(-14000, 14000, 3):
        assert native.sin_cos_q12(a) == (fp.sin_q12(a), fp.cos_q12(a)), a


def test_atan2_table_matches():
    rng = np.random.default_rng(3)
    pairs = [(0, 0), (0, -5), (3, 0), (-3, 0), (5, 5), (-5, -5), (-7, 2)]
    pairs += [tuple(int(v) for v in rng.integers(-10**6, 10**6, 2)) for _ in range(3000)]
    for y, x in pairs:
        assert native.atan2_mrad(y, x) == fp.atan2_mrad(y, x), (y, x)


def test_ring_pair_ranging_matches_on_random_inputs():
    rng = np.random.default_rng(5)
    cases = [(1, 0, 0, 0, 0, 0), (1, 5119, 3839, 5119, -1571, 3141), (16, 2560, 1920, 0, 0, 0)]
    for _ in range(4000):
        cases.append((int(rng.integers(1, 2400)), int(rng.integers(-400, 5600)),
                      int(rng.integers(-400, 4200)), int(rng.integers(0, 5120)),
                      int(rng.integers(-1700, 1700)), int(rng.integers(-3300, 3300))))
    for args in cases:
        assert native.locate_ring_pair(*args) == \
            dataclasses.astuple(ranging.locate_ring_pair(*args)), args


def test_ring_pair_ranging_refuses_what_it_cannot_compute_exactly():
    assert native.locate_ring_pair(0, 2560, 1920, 400, 0, 0) is None  # Python: ValueError
    assert native.locate_ring_pair(-16, 2560, 1920, 400, 0, 0) is None
    assert native.locate_ring_pair(16, 2560, 1920, 400, 0, 0, f_px=0) is None
    assert native.locate_ring_pair(16, 16 * 160 + 16 * 2049, 1920, 400, 0, 0) is None
    assert native.locate_ring_pair(16, 2560, 1920, 400, 0, 0, d_um=100_001) is None


@pytest.mark.parametrize("detector", ["dual_plus", "spoke"])
def test_plus_detectors_slice_matches(exp1_corpus, detector):
    calls = [c for c in corpus.calls(exp1_corpus, corpus.read_index(exp1_corpus))
             if c.detector == detector]
    found = _check_calls(exp1_corpus, calls[::2])
    assert 0 < found < len(calls[::2])  # the slice has results found and calls without


def test_red_cylinder_slice_matches(marker_slice):
    calls = [c for c in corpus.calls(marker_slice, corpus.read_index(marker_slice))
             if c.detector == "red_cylinder"]
    assert calls and _check_calls(marker_slice, calls[:30]) > 0  # the slice sees the cylinder


def test_double_cross_slice_matches(marker_slice):
    calls = [c for c in corpus.calls(marker_slice, corpus.read_index(marker_slice))
             if c.detector == "double_cross"]
    found = _check_calls(marker_slice, calls[::2])
    assert 0 < found < len(calls[::2])  # the slice has the marker found and calls without


def _check_double_cross(rgb, yaw=0, pitch=0, f_px=350):
    res, ops = double_cross.detect_double_cross(rgb, yaw, pitch, f_px)
    want = None if res is None else dataclasses.astuple(res)
    assert native.detect_double_cross_counted(rgb, yaw, pitch, f_px) == (want, ops.as_tuple())
    return want is not None


def test_double_cross_matches_on_drawn_markers():
    from test_vision_002_double_cross import draw_double_cross

    rng = np.random.default_rng(8)
    found = 0
    for k in range(24):
        rgb = draw_double_cross(float(rng.uniform(6, 60)), float(rng.uniform(90, 230)),
                                float(rng.uniform(60, 180)), rot=float(rng.uniform(-0.5, 0.5)),
                                seed=k, right_scale=float(rng.uniform(0.6, 1.6)),
                                crosses=((-1, 1), (-1, 1), (-1, 1), (1,))[k % 4])
        if k % 3 == 0:  # sensor noise: the threshold follows it
            noise = rng.normal(0, 4 + 3 * (k % 5), rgb.shape[:2])[..., None]
            rgb = np.clip(rgb + noise, 0, 255).astype(np.uint8)
        found += _check_double_cross(rgb, int(rng.integers(-1600, 1600)),
                                     int(rng.integers(-900, 900)), int(rng.integers(200, 700)))
    assert 8 < found < 24


@pytest.mark.parametrize("seed", range(24))
def test_double_cross_matches_on_random_frames(seed):
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(4, 90, 2))
    if seed % 3 == 0:  # smooth, textured and two-level frames of odd sizes
        yy, xx = np.mgrid[0:h, 0:w]
        img = 128 + 100 * np.sin(xx / rng.uniform(1, 6)) * np.cos(yy / rng.uniform(1, 6))
    elif seed % 3 == 1:
        img = np.where(rng.random((h, w)) < 0.5, 20, 235)
    else:
        img = rng.integers(0, 256, (h, w))
    rgb = np.repeat(np.clip(img, 0, 255).astype(np.uint8)[..., None], 3, axis=2)
    _check_double_cross(rgb, int(rng.integers(-3000, 3000)), int(rng.integers(-1500, 1500)))


@pytest.mark.parametrize("value", [0, 255])
def test_double_cross_uniform_frames_not_found(value):
    rgb = np.full((240, 320, 3), value, np.uint8)
    assert native.detect_double_cross(rgb) is None
    assert double_cross.detect_double_cross(rgb)[0] is None


def test_small_corpus_slice_matches(tmp_path):
    record(tmp_path, ["paper000-exp1"], time_limit_s=6.0)
    idx = corpus.read_index(tmp_path)
    assert idx["frames"]
    for fr in idx["frames"][:12]:
        _check_front_end(corpus.load_frame(tmp_path, fr))
    calls = [c for c in corpus.calls(tmp_path, idx) if c.detector == "radial_symbol"]
    assert _check_calls(tmp_path, calls[:40]) > 0  # the slice sees the symbol


@pytest.mark.slow
def test_whole_corpus_matches(tmp_path):
    from mobigrasp.services.run_job import shipped_scenarios

    record(tmp_path, [p.stem for p in shipped_scenarios()])
    idx = corpus.read_index(tmp_path)
    assert len(idx["scenarios"]) == 6
    for fr in idx["frames"]:
        _check_front_end(corpus.load_frame(tmp_path, fr))
    assert _check_calls(tmp_path, corpus.calls(tmp_path, idx)) > 0


@pytest.mark.parametrize("seed", range(30))
def test_red_roi_matches_on_drawn_red_pieces(seed):
    """Red boxes, stacked pieces and clutter of any size, some cut by the frame's edges."""
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(20, 130, 2))
    rgb = rng.integers(0, 90, (h, w, 3), dtype=np.uint8)
    for _ in range(int(rng.integers(0, 6))):
        x, y = int(rng.integers(-5, w)), int(rng.integers(-5, h))
        bw, bh = int(rng.integers(1, 40)), int(rng.integers(1, 60))
        colour = (int(rng.integers(120, 256)), int(rng.integers(0, 50)), int(rng.integers(0, 50)))
        rgb[max(0, y):max(0, y + bh), max(0, x):max(0, x + bw)] = colour
        if rng.random() < 0.5:  # a dark ring across it: the piece splits into stacked parts
            ry = y + bh // 2
            rgb[max(0, ry):max(0, ry + 2), max(0, x):max(0, x + bw)] = 10
    roi, _ = red_cylinder.detect_red_roi(rgb)
    want = None if roi is None else native.red_roi_tuple(roi)
    assert native.detect_red_roi(rgb) == want


@pytest.mark.parametrize("scale_b", [1.0, 1.3, 1.38, 1.5])
def test_dual_plus_pair_size_rule_matches(scale_b):
    """The pair's size rule (within 2:1) is the same in C: on and either side of the bound."""
    from test_vision_000_dual_plus import _plus_pair_frame

    _check_plus(_plus_pair_frame(scale_b))


def _check_plus(rgb, alpha_mrad=-1571, f_px=611, u0_px=160) -> tuple[bool, bool]:
    """Both "+" detectors in C and in Python on one frame, results and counts; which found."""
    res, ops = dual_plus.detect_dual_plus(rgb, alpha_mrad, f_px, u0_px)
    want = None if res is None else dataclasses.astuple(res)
    assert native.detect_dual_plus_counted(rgb, alpha_mrad, f_px, u0_px) == (
        want, ops.as_tuple())
    sp, sp_ops = spoke.detect_spoke(rgb)
    sp_want = None if sp is None else dataclasses.astuple(sp)
    assert native.detect_spoke_counted(rgb) == (sp_want, sp_ops.as_tuple())
    return want is not None, sp_want is not None


def test_plus_detectors_count_on_rendered_views():
    """The camera renderer's dual "+" and spoke views, clean and degraded (blur, noise,
    brightness)."""
    from mobigrasp.mcu_sim.world import camera_views as views
    from mobigrasp.mcu_sim.world.camera import CameraOptions, render

    options = (CameraOptions(), CameraOptions(noise_std=8.0, blur_px=2.0, brightness=0.7),
               CameraOptions(noise_std=8.0, blur_px=2.0, brightness=1.3))
    rng = np.random.default_rng(12)
    found = [0, 0]
    for i in range(18):
        v = (views.dual_plus, views.spoke, views.empty)[i % 3](rng)
        rgb = render(v.scene, v.cam_pos_w, v.R_wc, v.intr, options[i // 3 % 3],
                     np.random.default_rng(i))
        pair, one = _check_plus(rgb, int(rng.integers(-1600, 0)), int(rng.integers(300, 700)),
                                int(rng.integers(120, 200)))
        found[0] += pair
        found[1] += one
    assert found[0] > 0 and found[1] > 0


def _plus_polygon(cu: float, cv: float, arm: float, half_w: float, turn: float) -> np.ndarray:
    """The outline of a "+" of arms ``arm`` px from the centre, ``2 half_w`` wide, turned."""
    a, w = arm, half_w
    pts = np.array([(w, w), (a, w), (a, -w), (w, -w), (w, -a), (-w, -a), (-w, -w), (-a, -w),
                    (-a, w), (-w, w), (-w, a), (w, a)], float)
    c, s = np.cos(turn), np.sin(turn)
    return np.round(pts @ np.array([[c, s], [-s, c]]) + (cu, cv)).astype(np.int32)


@pytest.mark.parametrize("seed", range(30))
def test_plus_detectors_count_on_random_frames(seed):
    """Frames of any size with "+" of any size, turn and contrast, pairs, bars and blobs, some
    cut by the border, some noisy; and frames of noise alone."""
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(24, 200, 2))
    if seed % 5 == 4:
        rgb = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
        if seed % 10 == 9:  # two levels: many dark components of every shape
            rgb = (rng.random((h, w, 1)) < 0.5).repeat(3, axis=2) * np.uint8(200) + np.uint8(30)
        _check_plus(rgb)
        return
    img = np.full((h, w), int(rng.integers(150, 250)), np.uint8)
    for _ in range(int(rng.integers(0, 4))):  # bars and blobs
        x, y = int(rng.integers(-10, w)), int(rng.integers(-10, h))
        cv2.rectangle(img, (x, y), (x + int(rng.integers(2, 40)), y + int(rng.integers(2, 40))),
                      int(rng.integers(0, 90)), -1)
    arm = float(rng.uniform(3, min(h, w) / 6))
    cu, cv = float(rng.uniform(0, w / 2)), float(rng.uniform(arm, h - arm))
    turn = float(rng.uniform(-0.7, 0.7))
    step = float(rng.uniform(2.5, 5.0)) * arm  # the pair's spacing: about the card's
    for k in range(int(rng.integers(1, 4))):  # one "+", a pair, or three in a row
        scale = float(rng.uniform(0.7, 1.4)) if k else 1.0
        du, dv = k * step * np.cos(turn / 3), k * step * np.sin(turn / 3)
        cv2.fillPoly(img, [_plus_polygon(cu + du, cv + dv, arm * scale,
                                         arm * scale * float(rng.uniform(0.2, 0.45)), turn)],
                     int(rng.integers(0, 60)))
    if seed % 3 == 0:
        img = cv2.GaussianBlur(img, (3, 3), 0)
    if seed % 2:
        img = np.clip(img + rng.normal(0, 6, img.shape), 0, 255).astype(np.uint8)
    _check_plus(np.repeat(img[:, :, None], 3, axis=2), int(rng.integers(-1600, 0)),
                int(rng.integers(200, 800)), int(rng.integers(0, w)))


def _open_rings_frame(seed: int) -> np.ndarray:
    """Card with 2-5 wide open ellipses (candidates that fail the ring test, tried first) and
    one small closed ring (tried last): the local re-thresholding budget decides on some."""
    rng = np.random.default_rng(seed)
    img = np.full((240, 320), 235, np.uint8)
    for _ in range(int(rng.integers(2, 6))):
        centre = (int(rng.integers(40, 280)), int(rng.integers(30, 210)))
        axes = (int(rng.integers(25, 45)), int(rng.integers(15, 28)))
        cv2.ellipse(img, centre, axes, 0, 40, 320, 20, 3)
    centre = (int(rng.integers(40, 280)), int(rng.integers(30, 210)))
    cv2.ellipse(img, centre, (18, 12), 0, 0, 360, 20, 4)
    return np.repeat(img[:, :, None], 3, axis=2)


def test_radial_symbol_local_budget_matches(monkeypatch):
    decided = 0
    for seed in range(40):
        rgb = _open_rings_frame(seed)
        res, ops = radial_symbol.detect_radial_symbol(rgb)
        want = None if res is None else dataclasses.astuple(res)
        assert native.detect_radial_symbol_counted(rgb) == (want, ops.as_tuple()), seed
        with monkeypatch.context() as m:  # no budget: the ring is found on more frames
            m.setattr(radial_symbol, "LOCAL_BUDGET_NUM", 1000)
            dark_blobs.forget_front_end()
            unbounded, _ = radial_symbol.detect_radial_symbol(rgb)
        decided += res is None and unbounded is not None
    assert decided >= 5
