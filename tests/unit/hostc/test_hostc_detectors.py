"""The C program's detector table (hostc/detectors.c) against the Python host's detectors
(host/app_factory.py over host/vision/registry.py) on the frames of the first seconds of
paper002-marker: each detector's result, its out words and JSON, and the operation counts it
charges (the modelled ARM9 time); the double cross's pose from the newest telemetry."""

from __future__ import annotations

import json

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mobigrasp import hostc
from mobigrasp.calib import corpus
from mobigrasp.host import arm_calib
from mobigrasp.host.app import jsonable
from mobigrasp.host.vision import registry

FFI, C = hostc.lib()
ENCODER = json.JSONEncoder(sort_keys=True, separators=(",", ":"))  # the DONE's
NAMES = [FFI.string(C.mg_detector_names[i]).decode() for i in range(C.MG_N_DETECTORS)]
PORTED = ("double_cross", "red_cylinder", "red_roi", "held_fill")
MAX_DETECTORS = dict(FFI.typeof("mg_app_t").fields)["detectors"].type.length


def _table(f_px: int):
    app = FFI.new("mg_app_t *")
    dets = FFI.new("mg_detectors_t *")
    table = FFI.new("mg_detector_t[]", MAX_DETECTORS)
    n = C.mg_detectors_table(dets, app, f_px, table, MAX_DETECTORS)
    assert n == C.MG_N_DETECTORS
    return app, dets, table


def _run_c(table, name: str, rgb: np.ndarray, q=(0, 0, 0, 0, 0, 0)):
    d = table[NAMES.index(name)]
    assert FFI.string(d.name).decode() == name
    out = FFI.new("mg_detection_t *")
    buf = np.ascontiguousarray(rgb)
    snap = FFI.new("int32_t[8]", list(q) + [0, 0])
    d.detect(d.ctx, FFI.cast("uint8_t *", buf.ctypes.data), buf.shape[1], buf.shape[0], snap,
             out)
    return out


def _check(table, name: str, rgb: np.ndarray, cam, q) -> bool:
    res, ops = registry.row(name).host_call(rgb, cam, q)
    out = _run_c(table, name, rgb, q)
    assert out.found == (res is not None)
    assert FFI.string(out.json).decode() == ENCODER.encode(jsonable(res))
    assert hostc.ops_tuple(out.ops) == ops.as_tuple()  # the same modelled ARM9 time
    return res is not None


def test_the_table_on_recorded_frames(marker_slice):
    idx = corpus.read_index(marker_slice)
    shas = {f["file"]: f["sha256"] for f in idx["frames"]}
    calls = [c for c in corpus.calls(marker_slice, idx) if c.detector in PORTED]
    assert calls
    found = {}
    tables = {}
    for c in calls[::3]:
        rgb = corpus.load_frame(marker_slice, {"file": c.frame_file,
                                               "sha256": shas[c.frame_file]})
        if c.camera[0] not in tables:
            tables[c.camera[0]] = _table(c.camera[0])
        table = tables[c.camera[0]][2]
        q = tuple(int(v) for v in c.args[0]) if c.args else (0, 0, -1571, 0, 0, 0)
        for name in ("red_roi", "red_cylinder", c.detector):
            found[name] = found.get(name, 0) + _check(table, name, rgb, c.camera, q)
    assert found.get("double_cross", 0) > 0 and found.get("red_roi", 0) > 0


@settings(max_examples=60, deadline=None)
@given(st.integers(8, 80), st.integers(8, 60), st.integers(0, 2**32 - 1),
       st.sampled_from(PORTED))
def test_the_table_on_random_frames(w, h, seed, name):
    """Frames of any size from 8 px a side (the red detectors refuse smaller ones)."""
    rgb = np.random.default_rng(seed).integers(0, 256, (h, w, 3), dtype=np.uint8)
    _, _, table = _table(350)
    _check(table, name, rgb, (350, 160, 120), (0, 0, -1571, 0, 0, 0))


def test_unported_detectors_find_nothing_and_charge_nothing():
    _, _, table = _table(611)
    rgb = np.zeros((24, 32, 3), np.uint8)
    for name in set(NAMES) - set(PORTED):
        out = _run_c(table, name, rgb)
        assert (out.found, FFI.string(out.json), hostc.ops_tuple(out.ops)) == (
            0, b"null", (0,) * 11)


@settings(max_examples=80, deadline=None)
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
