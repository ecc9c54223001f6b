"""The C program's detector table (hostc/detectors.c) against the Python host's detectors
(host/app_factory.py over host/vision/registry.py) on the frames of the first seconds of
paper002-marker and of paper000-exp1 and on random frames: each detector's result, its out
words and JSON, and the operation counts it charges (the modelled ARM9 time); the pose of the
double cross and the dual "+" from the newest telemetry; the 000 detectors' shared front end,
computed by the first of a frame and reused by the others."""

from __future__ import annotations

import json

import numpy as np
from clipped_frame import clipped_far_frame
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.calib import corpus
from mobigrasp.host import app_factory, arm_calib
from mobigrasp.host.app import jsonable
from mobigrasp.host.vision import registry
from mobigrasp.mcu_sim.world import camera_views
from mobigrasp.mcu_sim.world.camera import CameraOptions, render

FFI, C = hostc.lib()
ENCODER = json.JSONEncoder(sort_keys=True, separators=(",", ":"))  # the DONE's
NAMES = [FFI.string(C.mg_detector_names[i]).decode() for i in range(C.MG_N_DETECTORS)]
THE_000 = ("radial_symbol", "dual_plus", "spoke", "radial_cut")
MAX_DETECTORS = dict(FFI.typeof("mg_app_t").fields)["detectors"].type.length


def _table(f_px: int):
    app = FFI.new("mg_app_t *")
    dets = FFI.new("mg_detectors_t *")
    table = FFI.new("mg_detector_t[]", MAX_DETECTORS)
    n = C.mg_detectors_table(dets, app, f_px, table, MAX_DETECTORS)
    assert n == C.MG_N_DETECTORS
    return app, dets, table


def _run_c(table, name: str, rgb: np.ndarray, q=(0, 0, 0, 0, 0, 0), ready: int = 0):
    """Detector ``name`` on ``rgb``; ``ready``: the front end is the one the detector before
    computed (as the program says to the second 000 detector of a frame)."""
    d = table[NAMES.index(name)]
    assert FFI.string(d.name).decode() == name
    out = FFI.new("mg_detection_t *")
    buf = np.ascontiguousarray(rgb)
    snap = FFI.new("int32_t[8]", list(q) + [0, 0])
    d.detect(d.ctx, FFI.cast("uint8_t *", buf.ctypes.data), buf.shape[1], buf.shape[0], snap,
             ready, out)
    return out


def _check(table, name: str, rgb: np.ndarray, cam, q, ready: int = 0) -> bool:
    res, ops = registry.row(name).host_call(rgb, cam, q)
    out = _run_c(table, name, rgb, q, ready)
    assert out.found == (res is not None)
    assert FFI.string(out.json).decode() == ENCODER.encode(jsonable(res))
    assert hostc.ops_tuple(out.ops) == ops.as_tuple()  # the same modelled ARM9 time
    return res is not None


def _check_recorded(folder, detectors, also) -> dict:
    """Every third call of ``detectors`` in the corpus at ``folder``, each frame given to its
    detector and to those in ``also`` too, a 000 detector after another one reusing its front
    end; the results found per detector."""
    idx = corpus.read_index(folder)
    shas = {f["file"]: f["sha256"] for f in idx["frames"]}
    calls = [c for c in corpus.calls(folder, idx) if c.detector in detectors]
    assert calls
    found: dict = {}
    tables: dict = {}
    for c in calls[::3]:
        rgb = corpus.load_frame(folder, {"file": c.frame_file, "sha256": shas[c.frame_file]})
        if c.camera[0] not in tables:
            tables[c.camera[0]] = _table(c.camera[0])
        table = tables[c.camera[0]][2]
        q = tuple(int(v) for v in c.args[0]) if c.args else (0, 0, -1571, 0, 0, 0)
        ready = 0
        for name in dict.fromkeys((*also, c.detector)):
            found[name] = found.get(name, 0) + _check(table, name, rgb, c.camera, q, ready)
            ready = int(name in THE_000)
    return found


def test_the_table_on_recorded_frames(marker_slice):
    found = _check_recorded(marker_slice, ("double_cross", "red_cylinder", "red_roi",
                                           "held_fill"), ("red_roi", "red_cylinder"))
    assert found.get("double_cross", 0) > 0 and found.get("red_roi", 0) > 0


def test_the_000_rows_on_recorded_frames(exp1_corpus):
    """paper000-exp1's frames: the search's radial symbol, the approach's dual "+" and the
    spoke over the object, each frame given to all four (the cut symbol too)."""
    found = _check_recorded(exp1_corpus, THE_000, THE_000)
    assert all(found.get(name, 0) > 0 for name in THE_000[:3]), found


def test_the_cut_symbol_on_rendered_frames():
    """A symbol near the camera, its centre beyond the left or right border: cut, the same
    box, side, JSON and counts as the Python detector's."""
    _, _, table = _table(611)
    rng = np.random.default_rng(7)
    found = 0
    for side in (-1, 1, -1, 1):
        v = camera_views.radial_cut(rng, side * 180.0)
        rgb = render(v.scene, v.cam_pos_w, v.R_wc, v.intr, CameraOptions(),
                     np.random.default_rng(0))
        found += _check(table, "radial_cut", rgb, (611, 160, 120), (0, 0, -1571, 0, 0, 0))
    assert found >= 3


def test_the_000_rows_on_a_clipped_frame():
    """A frame whose bright level clips (camera gain 1.7): each 000 row as the Python one, the
    radial symbol read."""
    _, _, table = _table(611)
    rgb = clipped_far_frame()[1]
    found = {n: _check(table, n, rgb, (611, 160, 120), (0, 0, -1571, 0, 0, 0)) for n in THE_000}
    assert found["radial_symbol"]


@examples(60)
@given(st.integers(8, 80), st.integers(8, 60), st.integers(0, 2**32 - 1),
       st.sampled_from(NAMES))
def test_the_table_on_random_frames(w, h, seed, name):
    """Frames of any size from 8 px a side (the red detectors refuse smaller ones, the 000
    detectors those under 16 px)."""
    rgb = np.random.default_rng(seed).integers(0, 256, (h, w, 3), dtype=np.uint8)
    if name in THE_000 and min(w, h) < 16:
        out = _run_c(_table(611)[2], name, rgb)
        assert (out.found, FFI.string(out.json), hostc.ops_tuple(out.ops)) == (
            0, b"null", (0,) * 11)
        return
    _, _, table = _table(350)
    _check(table, name, rgb, (350, 160, 120), (0, 0, -1571, 0, 0, 0))


def test_the_000_rows_share_their_front_end():
    """The four 000 detectors start from one front end, charged once a frame: the row's id
    and its time on a frame of each size are the Python host's (host/app_factory.py
    front_ends)."""
    _, _, table = _table(611)
    python = app_factory.front_ends(THE_000)
    ids = {table[NAMES.index(name)].front_end for name in THE_000}
    assert len(ids) == 1 and ids.pop() > 0
    assert {python[name][0] for name in THE_000} == {python[THE_000[0]][0]}
    for name in THE_000:
        d = table[NAMES.index(name)]
        for h, w in ((16, 16), (240, 320), (480, 640), (37, 203)):
            assert d.front_end_us(h, w) == python[name][1](h, w)
    for name in set(NAMES) - set(THE_000):
        assert table[NAMES.index(name)].front_end == 0


def test_a_ready_front_end_is_not_computed_again(exp1_corpus):
    """A 000 detector told its front end is ready reads the one computed before it: given
    another frame of the same size (a blank one), it finds what it finds on the first frame,
    with the same counts."""
    idx = corpus.read_index(exp1_corpus)
    shas = {f["file"]: f["sha256"] for f in idx["frames"]}
    _, _, table = _table(611)
    checked = 0
    for c in corpus.calls(exp1_corpus, idx):
        if c.detector != "radial_symbol" or checked == 3:
            continue
        rgb = corpus.load_frame(exp1_corpus, {"file": c.frame_file, "sha256": shas[c.frame_file]})
        first = _run_c(table, "radial_symbol", rgb)
        if not first.found:
            continue
        blank = np.full_like(rgb, 255)
        again = _run_c(table, "radial_symbol", blank, ready=1)
        assert (again.found, FFI.string(again.json), hostc.ops_tuple(again.ops)) == (
            1, FFI.string(first.json), hostc.ops_tuple(first.ops))
        assert not _run_c(table, "radial_symbol", blank).found  # computed: nothing on it
        checked += 1
    assert checked == 3


@examples(80)
@given(st.none() | st.lists(st.integers(0, 3000), min_size=6, max_size=6))
def test_the_double_cross_reads_the_newest_telemetry_pose(pulses):
    app, _, table = _table(611)
    if pulses is not None:
        app.link.has_telemetry = 1
        app.link.telemetry.servo_us[0:6] = pulses
    snap = FFI.new("int32_t[8]")
    d = table[NAMES.index("double_cross")]
    d.snapshot(d.ctx, snap)
    if pulses is None or not all(500 <= p <= 2500 for p in pulses):
        want = (0, 0, -1571, 0, 0, 0)  # the rest pose: no telemetry, or no angle for a pulse
    else:
        want = arm_calib.pulses_to_joints_mrad(tuple(pulses))
    assert tuple(snap[0:6]) == tuple(want)
