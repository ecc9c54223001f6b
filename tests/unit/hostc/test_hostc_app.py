"""The C host's main loop and lockstep driver (hostc/app.c, hostc/lockstep_driver.c) against
host/app.py served by drivers/lockstep.py: one scripted task and two scripted detectors drive
both programs (the C through callbacks), sharing a front end and one standing in for the
other on some frames (a fallback), the same GRANTs bring the same MCU bytes and camera frames,
and every DONE and every byte written to the serial port is the same."""

from __future__ import annotations

import json

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from rig_fakes import BufferPort

from mobigrasp import hostc
from mobigrasp.cosim import lockstep as ls
from mobigrasp.drivers.lockstep import LockstepClient
from mobigrasp.host.app import HostApp, HostConfig
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.task.machine import TaskEvent, TaskOutputs
from mobigrasp.protocol import messages as m

FFI, C = hostc.lib()
NAMES = ("blob", "cross")


def _dumps(v) -> str:
    return json.dumps(v, sort_keys=True, separators=(",", ":"))


class Script:
    """The task's step k: what it commands, its state, cost and detail, from a drawn table;
    which detectors it needs; the detections it was handed, as both programs gave them."""

    def __init__(self, steps: list[dict]) -> None:
        self.steps = steps
        self.k = 0
        self.seen: list = []
        self.state = "INIT"

    def needed(self) -> list[str]:
        return [n for i, n in enumerate(NAMES) if (self.k // (3 + i)) % 2 == 0]

    def fallbacks(self) -> dict[str, str]:
        """Every other pair of steps "cross" stands in for "blob" (runs when it found none)."""
        return {"cross": "blob"} if (self.k // 2) % 2 == 0 else {}

    def step(self, now_us: int, detections: dict) -> dict:
        s = self.steps[self.k % len(self.steps)]
        self.seen.append((now_us, sorted(detections.items())))
        self.k += 1
        out = dict(s)
        if "state" in s and s["state"] != self.state:
            out["transitions"] = [(now_us, self.state, s["state"], f"step {self.k}")]
            self.state = s["state"]
        return out


def _py_task(script: Script):
    class Task:
        def detectors_needed(self):
            return script.needed()

        def detector_fallbacks(self):
            return script.fallbacks()

        def step(self, now_us, inputs):
            s = script.step(now_us, inputs)
            return TaskOutputs(
                s.get("servos"), s.get("wheels"), s.get("gripper"),
                [TaskEvent(*t) for t in s.get("transitions", [])], script.state,
                s.get("detail") or {}, OpCounts(alu=s["cycles"]))
    return Task()


def _detect(name: str, rgb: np.ndarray):
    total = int(rgb.astype(np.int64).sum())
    result = None if total % 5 == 0 else {"sum": total % 997, "w": int(rgb.shape[1]),
                                           "who": name}
    return result, OpCounts(pixels_read=rgb.size * (3 + NAMES.index(name)),
                            alu=total % 7 * 2_000_000)


def _c_task(script: Script, keep: list):
    @FFI.callback("void(void *, mg_app_t *, int64_t, const mg_detection_t *, const int32_t *,"
                  " mg_task_output_t *)")
    def step(ctx, app, now_us, detections, present, out):
        got = {NAMES[i]: json.loads(FFI.string(detections[i].json).decode())
               if detections[i].found else None for i in range(len(NAMES)) if present[i]}
        s = script.step(now_us, got)
        cstr = []

        def c(text: str):
            cstr.append(FFI.new("char[]", text.encode()))
            return cstr[-1]

        if s.get("servos") is not None:
            out.has_servos, out.servo_mrad = 1, s["servos"]
        if s.get("gripper") is not None:
            out.has_gripper, out.gripper_permille = 1, s["gripper"]
        if s.get("wheels") is not None:
            out.has_wheels, out.wheels_mmps = 1, s["wheels"]
        out.state = c(script.state)
        out.ops.alu = s["cycles"]
        for i, (t, a, b, why) in enumerate(s.get("transitions", [])):
            out.transitions[i] = {"t_us": t, "from": c(a), "to": c(b), "why": c(why)}
            out.n_transitions = i + 1
        for i, (key, value) in enumerate(sorted((s.get("detail") or {}).items())):
            out.detail[i] = {"key": c(key), "json": c(_dumps(value))}
            out.n_detail = i + 1
        out.detail_has_plan = (s.get("detail") or {}).get("plan") is not None
        keep.append(cstr)

    @FFI.callback("uint32_t(void *)")
    def needed(ctx):
        return sum(1 << NAMES.index(n) for n in script.needed())

    @FFI.callback("int32_t(void *, int32_t)")
    def fallback_of(ctx, det):
        primary = script.fallbacks().get(NAMES[det])
        return -1 if primary is None else NAMES.index(primary)

    keep += [step, needed, fallback_of]
    return FFI.new("mg_task_if_t *", {"ctx": FFI.NULL, "step": step,
                                      "detectors_needed": needed, "fallback_of": fallback_of})


def _front_end_us(h: int, w: int) -> int:
    """The front end both detectors start from (its modelled µs on h x w)."""
    return 3 * h * w + 5


def _c_detectors(keep: list, front_end: dict):
    """The two detectors over one front end: a copy of the frame, made by the first of a frame
    (counted in ``front_end["computed"]``) and read by the one after it when the program says
    it is ready (a front end of another frame would give other results than Python's)."""
    table = FFI.new("mg_detector_t[]", len(NAMES))
    fe_us = FFI.callback("int64_t(int32_t, int32_t)", _front_end_us)
    keep.append(fe_us)
    front_end["computed"] = 0
    for i, name in enumerate(NAMES):
        @FFI.callback("void(void *, const uint8_t *, int32_t, int32_t, const int32_t *,"
                      " int32_t, mg_detection_t *)")
        def detect(ctx, rgb, w, h, snap, ready, out, name=name):
            if not ready:
                front_end["img"] = np.frombuffer(FFI.buffer(rgb, w * h * 3),
                                                 np.uint8).reshape(h, w, 3).copy()
                front_end["computed"] += 1
            result, ops = _detect(name, front_end["img"])
            out.found = result is not None
            out.ops.pixels_read, out.ops.alu = ops.pixels_read, ops.alu
            out.json = _dumps(result).encode()
        keep += [detect, FFI.new("char[]", name.encode())]
        table[i] = {"name": keep[-1], "ctx": FFI.NULL, "snapshot": FFI.NULL, "detect": detect,
                    "front_end": 1, "front_end_us": fe_us}
    return table


STEP = st.fixed_dictionaries(
    {"cycles": st.integers(0, 4_000_000) | st.integers(4_000_000, 14_000_000)},
    optional={"servos": st.lists(st.integers(-3500, 3500), min_size=6, max_size=6),
              "gripper": st.integers(-100, 1100),
              "wheels": st.lists(st.integers(-1500, 1500), min_size=2, max_size=2),
              "state": st.sampled_from(["INIT", "SEARCH", "APPROACH", "GRASP", "DONE"]),
              "detail": st.dictionaries(st.sampled_from(["plan", "e_mrad", "why", "pose",
                                                         "grasp_circle"]),
                                        st.integers(-99, 99) | st.text(max_size=5)
                                        | st.lists(st.integers(0, 9), max_size=3)
                                        # 001's arrival on the grasp circle: its error kept
                                        | st.fixed_dictionaries({
                                            "axle_mm": st.integers(0, 999),
                                            "error_mm": st.integers(-999, 999),
                                            "path_error_mm": st.none() | st.integers(0, 99)}),
                                        max_size=3)})


@st.composite
def mcu_stream(draw, end_us: int) -> list[tuple[int, bytes]]:
    """(arrival_us, bytes) of the MCU: HELLO_ACK, telemetry every 10 ms (its handshake flag,
    now and then a reset), and ACKs/NACKs of the first seqs."""
    out = [(draw(st.integers(1_000, 30_000)), m.encode_message(
        m.HelloAck(1, "atmega128-fw"), 0))]
    for t in range(5_000, end_us, 10_000):
        flags = draw(st.sampled_from([m.FLAG_HANDSHAKE] * 12 + [m.FLAG_RESET, 0]))
        servo = tuple(draw(st.sampled_from([1500, 1200, 0])) for _ in range(6))
        out.append((t, m.encode_message(m.Telemetry(t, t // 100, -t // 90, servo, (2500,) * 5,
                                                    flags, 0, 0, 0, 0), t // 10_000 % 256)))
    for _ in range(draw(st.integers(0, 12))):
        seq = draw(st.integers(0, 40))
        msg = m.Ack(seq) if draw(st.booleans()) else m.Nack(seq, 4)
        out.append((draw(st.integers(0, end_us - 1)), m.encode_message(msg, 0)))
    return sorted(out, key=lambda x: x[0])


@examples(25)
@given(st.lists(STEP, min_size=1, max_size=12), st.data())
def test_host_program_served_by_the_rig(steps, data):
    end_us = data.draw(st.integers(200_000, 1_300_000))
    mcu = data.draw(mcu_stream(end_us))
    frames = [(t, t + data.draw(st.integers(0, 40_000)),
               data.draw(st.sampled_from([(8, 6), (5, 4), (0, 0)])))
              for t in range(0, end_us, data.draw(st.integers(9_000, 70_000)))]
    quanta = data.draw(st.lists(st.integers(1_000, 30_000), min_size=1, max_size=8))
    py_script, c_script = Script(steps), Script(steps)
    port = BufferPort()
    app = HostApp(_py_task(py_script), {n: (lambda rgb, n=n: _detect(n, rgb)) for n in NAMES},
                  lambda app, now, det: det, HostConfig(),
                  front_ends={n: ("grey", _front_end_us) for n in NAMES})
    client = LockstepClient(app, port)
    keep: list = []
    config = FFI.new("mg_host_config_t *")
    C.mg_host_config_default(config)
    capp = FFI.new("mg_app_t *")
    front_end: dict = {}
    C.mg_app_init(capp, config, _c_task(c_script, keep), _c_detectors(keep, front_end),
                  len(NAMES))
    driver = FFI.new("mg_lockstep_t *")
    C.mg_lockstep_init(driver, capp)
    done_buf = FFI.new("uint8_t[65536]")
    t, k, seq = 0, 0, 0
    while t < end_us:
        until = t + quanta[k % len(quanta)]
        k += 1
        chunks = [(a, b) for a, b in mcu if t <= a < until]
        blobs = []
        for cap, arr, (w, h) in frames:
            if t <= arr < until and cap <= arr:
                px = bytes(data.draw(st.binary(min_size=w * h * 3, max_size=w * h * 3)))
                blobs.append(ls.FrameBlob(seq, cap, arr, w, h, 3, px))
                seq += 1
        grant = ls.Grant(t, until, tuple((a, len(b)) for a, b in chunks), tuple(blobs))
        uart = b"".join(b for _, b in chunks)
        port.rx += uart
        want = ls.encode(client.serve(grant))
        client.after_done()
        wire = ls.encode(grant)
        kind, meta_len, blob_len = (FFI.new("int32_t *"), FFI.new("uint32_t *"),
                                    FFI.new("uint32_t *"))
        assert C.mg_ls_decode_header(wire[:13], kind, meta_len, blob_len) == 0
        cg = FFI.new("mg_ls_grant_t *")
        assert C.mg_ls_decode_grant(kind[0], wire[13:13 + meta_len[0]], meta_len[0],
                                    blob_len[0], cg) == 0
        pixels = [FFI.from_buffer(b.pixels) if b.pixels else FFI.NULL for b in blobs]
        c_pixels = FFI.new("uint8_t *[]", pixels or [FFI.NULL])
        n = C.mg_lockstep_serve(driver, cg, uart, c_pixels, done_buf, 65536)
        assert bytes(done_buf[0:n]) == want, ls.decode(want)
        assert bytes(driver.out[0:driver.out_len]) == bytes(port.tx)
        port.tx.clear()
        t = until
    assert c_script.seen == py_script.seen
    assert (capp.control_steps, capp.deadline_misses, capp.frames_dropped,
            capp.frames_processed, capp.replans) == (
        app.counters.control_steps, app.counters.deadline_misses,
        app.counters.frames_dropped, app.counters.frames_processed, app.replans)
    assert capp.events_lost == 0 and capp.frames_lost == 0
    assert front_end["computed"] == capp.frames_processed  # once a frame its detectors ran on
    # the first arrival on the grasp circle's error (the BYE's circle_error_mm)
    assert (capp.circle_error_mm if capp.has_circle_error else None) == app.circle_error_mm


def test_a_run_longer_than_the_load_windows_kept():
    """A run of more load windows than the program keeps (MG_LOAD_WINDOWS_KEPT, 32 s of 500 ms
    windows): the older are folded, never more than the kept are held, and every finished
    window is reported once, in order."""
    keep: list = []
    config = FFI.new("mg_host_config_t *")
    C.mg_host_config_default(config)
    capp = FFI.new("mg_app_t *")
    C.mg_app_init(capp, config, _c_task(Script([{}]), keep), _c_detectors(keep, {}),
                  len(NAMES))
    kept = len(capp.load_index) - 1  # MG_LOAD_WINDOWS_KEPT
    index, micro = FFI.new("int64_t[80]"), FFI.new("int64_t[80]")
    seen: list = []
    for until in range(100_000, 60_000_001, 100_000):
        C.mg_app_advance_to(capp, until)
        assert capp.n_loads <= kept
        n = C.mg_app_load_windows(capp, len(seen), index, micro, 80)
        seen += list(index[0:n])
    assert seen == list(range(len(seen))) and len(seen) == 60_000_000 // 500_000
