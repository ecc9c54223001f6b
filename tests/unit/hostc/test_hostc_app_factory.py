"""The detectors' glue of the C host (hostc/app_factory.c) and its held-fill kernel
(hostc/held_fill.c) against host/app_factory.py's detectors and host/vision: the kernels' out
words as the task reads them (002's frame), their sightings and their results' JSON in the
trace's detect event."""

from __future__ import annotations

import json

import detections as det
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.host.app import jsonable
from mobigrasp.host.task.sense import CAMERA_002
from mobigrasp.host.vision import held_fill, registry
from mobigrasp.host.vision.double_cross import level_pair
from mobigrasp.protocol import messages as m

FFI, C = hostc.lib()
SETTINGS = examples(150)
ENCODER = json.JSONEncoder(sort_keys=True, separators=(",", ":"))  # the DONE's
CROSS, RED, ROI, HELD = (registry.row(n) for n in ("double_cross", "red_cylinder", "red_roi",
                                                   "held_fill"))
I = st.integers(-2**20, 2**20)
PX = st.integers(-16, 400 * 16)


def words(name: str, res) -> list[int]:
    """A host result as its C kernel's out words (hostc/app_factory.h)."""
    if name == "double_cross":
        return [res.u1_q4, res.v1_q4, res.u2_q4, res.v2_q4, res.um_q4, res.vm_q4,
                res.d_pixel_q4, res.e_mrad, *res.votes]
    if name == "red_cylinder":
        return [res.u_c_q4, res.v_c_q4, res.ring1_v_q4, res.ring2_v_q4, res.d_pixel_q4,
                res.width_q4, *res.roi]
    if name == "red_roi":
        return [res.u_c_q4, res.v_c_q4, *res.roi, res.area_px, int(res.touches_edge)]
    return [*res.rgb, res.fill_permille]


RESULTS = {
    "double_cross": st.builds(lambda a, b, c, d, e, f, g, h, v1, v2: CROSS.result_type()(
        a, b, c, d, e, f, g, h, (v1, v2)), PX, PX, PX, PX, PX, PX, PX, I,
        st.integers(0, 999), st.integers(0, 999)),
    "red_cylinder": st.builds(lambda a, b, c, d, e, f, roi: RED.result_type()(
        a, b, c, d, e, f, roi), PX, PX, PX, PX, PX, PX,
        st.tuples(*[st.integers(0, 400)] * 4)),
    "red_roi": st.builds(lambda a, b, roi, area, edge: ROI.result_type()(
        a, b, roi, area, edge), PX, PX, st.tuples(*[st.integers(-2, 400)] * 4),
        st.integers(0, 10**5), st.booleans()),
    "held_fill": st.builds(lambda r, g, b, p: HELD.result_type()((r, g, b), p),
                           *[st.integers(0, 255)] * 3, st.integers(900, 1000)),
}
JSON = {"double_cross": C.mg_double_cross_json, "red_cylinder": C.mg_red_cylinder_json,
        "red_roi": C.mg_red_roi_json, "held_fill": C.mg_held_fill_json}
SIGHTING = {"double_cross": C.mg_double_cross_sighting,
            "red_cylinder": C.mg_red_cylinder_sighting, "red_roi": C.mg_red_roi_sighting}


@SETTINGS
@given(st.sampled_from(sorted(RESULTS)).flatmap(
    lambda name: st.tuples(st.just(name), RESULTS[name])), st.integers(100, 900))
def test_results_json_and_sightings(named, f_px):
    name, res = named
    w = words(name, res)
    out = FFI.new("char[512]")
    n = JSON[name](w, out, 512)
    assert FFI.string(out).decode() == ENCODER.encode(jsonable(res)) and n == len(
        FFI.string(out))
    assert JSON[name](w, out, 8) == 0  # too small: nothing, not a cut text
    if name in SIGHTING:
        s = FFI.new("mg_sighting_t *")
        ok = SIGHTING[name](w, f_px, s)
        want = registry.row(name).sighting_fn()(res, f_px)
        assert ((s.u_q4, s.v_q4, s.depth_mm_q4) if ok else None) == want


@SETTINGS
@given(st.floats(250, 3000), st.floats(-0.45, 0.45), st.floats(-1.4, 1.4),
       st.integers(250, 700))
def test_the_sighting_of_an_oblique_board(dist_mm, bearing, off_face, f_px):
    """The cylinder placed in the plane of a board seen obliquely (and the frontal model near
    its face): the C as the Python, on the crosses as the detector reports them."""
    res, _ = det.oblique_board(dist_mm, bearing, off_face, f_px)
    s = FFI.new("mg_sighting_t *")
    ok = C.mg_double_cross_sighting(words("double_cross", res), f_px, s)
    assert ((s.u_q4, s.v_q4, s.depth_mm_q4) if ok else None) == CROSS.sighting_fn()(res, f_px)


@SETTINGS
@given(*[st.none() | RESULTS[n] for n in ("double_cross", "red_cylinder", "red_roi",
                                           "held_fill")])
def test_the_frame_of_002(dc, rc, roi, fill):
    """The results as 002's task reads them: what its Python hooks take from the results."""
    f = FFI.new("mg_frame002_t *")
    keep = [FFI.new("int32_t[]", words(n, r)) if r is not None else FFI.NULL
            for n, r in zip(("double_cross", "red_cylinder", "red_roi", "held_fill"),
                            (dc, rc, roi, fill), strict=True)]
    C.mg_frame002_of(f, *keep, CAMERA_002.f_px)
    assert f.has_frame == 1
    assert (f.has_dc, f.has_rc, f.has_roi, f.has_held_fill) == tuple(
        int(r is not None) for r in (dc, rc, roi, fill))
    if dc is not None:
        assert (f.dc_um_q4, f.dc_vm_q4, f.dc_d_pixel_q4) == (dc.um_q4, dc.vm_q4, dc.d_pixel_q4)
        assert f.dc_level == int(level_pair(dc))
        seen = CROSS.sighting_fn()(dc, CAMERA_002.f_px)
        assert (tuple(FFI.unpack(FFI.cast("int32_t *", FFI.addressof(f.dc_sighting)), 3))
                if f.has_dc_sighting else None) == seen
    if rc is not None:
        assert (f.rc.u_c_q4, f.rc.v_c_q4, f.rc.d_pixel_q4, f.rc.width_q4) == (
            rc.u_c_q4, rc.v_c_q4, rc.d_pixel_q4, rc.width_q4)
    if roi is not None:
        seen = ROI.sighting_fn()(roi, CAMERA_002.f_px)
        assert (f.roi_u_c_q4, f.roi_v_c_q4) == (roi.u_c_q4, roi.v_c_q4)
        assert ((f.roi_sighting.u_q4, f.roi_sighting.v_q4, f.roi_sighting.depth_mm_q4)
                if f.has_roi_sighting else None) == seen
    if fill is not None:
        assert (tuple(f.held_rgb), f.held_permille) == (fill.rgb, fill.fill_permille)


def _held_c(rgb: np.ndarray):
    h, w = rgb.shape[:2]
    out = FFI.new("int32_t[4]")
    buf = np.ascontiguousarray(rgb)
    scratch = FFI.new("uint32_t[]", 3 * 256)  # MG_HELD_SCRATCH_WORDS
    ok = C.mg_held_fill(FFI.cast("uint8_t *", buf.ctypes.data), w, h, scratch, out)
    return HELD.result_type()(tuple(out[0:3]), out[3]) if ok else None


@pytest.mark.parametrize("seed", range(24))
def test_the_held_fill_kernel(seed):
    """Frames filled by a colour with noise, half filled, random: the same colour and share,
    the same charge."""
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(4, 90, 2))
    base = rng.integers(0, 256, 3)
    noise = int(rng.integers(0, 20 if seed % 3 == 0 else 60))
    rgb = np.clip(base + rng.integers(-noise, noise + 1, (h, w, 3)), 0, 255).astype(np.uint8)
    if seed % 3 == 1:  # a part of another colour
        rgb[: int(rng.integers(0, h)), :] = rng.integers(0, 256, 3).astype(np.uint8)
    elif seed % 3 == 2:
        rgb = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    want, ops = held_fill.detect_held_fill(rgb)
    assert _held_c(rgb) == want
    assert hostc.ops_tuple(C.mg_held_fill_ops(h, w)) == ops.as_tuple()
    if seed % 3 == 0:
        assert want is not None  # the filled frames are found


class _Link:
    """What InputBuilder reads of host/app_link.py's HostLink."""

    def __init__(self) -> None:
        self.telemetry = None
        self.mcu_resets = 0


class _App:
    def __init__(self) -> None:
        self.link = _Link()


TELEMETRY = st.tuples(st.integers(1_000, 60_000), st.integers(-300, 300), st.integers(-300, 300),
                      st.tuples(*[st.integers(500, 2500)] * 6),
                      st.tuples(*[st.sampled_from([65535, 0]) | st.integers(1, 4000)] * 5),
                      st.sampled_from([0, m.FLAG_GRIPPER_CLOSED, m.FLAG_HANDSHAKE]))


@SETTINGS
@given(st.lists(st.tuples(st.sampled_from(["tel", "tel", "step", "step", "reset"]),
                          st.integers(0, 300_000), TELEMETRY), max_size=60))
def test_the_input_builder(ops):
    """Telemetry frames, MCU resets and steps: the same pose, joints, sonars and gripper state
    in the inputs of every step."""
    from mobigrasp.host.app_factory import InputBuilder
    py, app = InputBuilder(), _App()
    c, link = FFI.new("mg_input_builder_t *"), FFI.new("mg_host_link_t *")
    C.mg_input_builder_init(c)
    inp = FFI.new("mg_task_inputs_t *")
    now, t_mcu, enc = 0, 0, [0, 0]
    for kind, dt, (dt_mcu, dl, dr, servo, sonar, flags) in ops:
        now += dt
        if kind == "tel":
            t_mcu, enc = t_mcu + dt_mcu, [enc[0] + dl, enc[1] + dr]
            app.link.telemetry = m.Telemetry(t_mcu, enc[0], enc[1], servo, sonar, flags,
                                             0, 0, 0, 0)
            link.has_telemetry, link.counters.telemetry = 1, link.counters.telemetry + 1
            link.telemetry.time_us, link.telemetry.enc_left, link.telemetry.enc_right = (
                t_mcu, enc[0], enc[1])
            link.telemetry.servo_us, link.telemetry.sonar_mm = servo, sonar
            link.telemetry.flags = flags
        elif kind == "reset":
            app.link.mcu_resets += 1
            link.mcu_resets += 1
            t_mcu, enc = 0, [0, 0]
        else:
            want = py(app, now, {})
            C.mg_input_builder_step(c, link, now, FFI.NULL, inp)
            assert (tuple(inp.joints_mrad) if inp.has_joints else None) == want.joints_mrad
            assert (inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps) == (
                want.x_mm, want.y_mm, want.heading_mrad, want.v_mmps)
            assert tuple(inp.sonar_mm)[:inp.n_sonar] == want.sonar_mm
            assert bool(inp.grasp_closed) == want.grasp_closed and inp.frame == FFI.NULL
