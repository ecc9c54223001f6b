"""HostApp with lower bounds of the detectors' cost (vision_bounds): a tick before a job's bounded
end does not run its detectors, and everything modelled is what running them at once gives."""

import numpy as np
from rig_fakes import FakeOutputs, blob_detector, build_inputs

from mobigrasp.host.app import HostApp, HostConfig
from mobigrasp.host.budget import OpCounts
from mobigrasp.protocol import messages as m

QUANTUM = 5_000


def _ack_hello(app, at_us):
    hello_seq = app.link._hello_seq
    app.on_uart(m.encode_message(m.Ack(acked_seq=hello_seq), 0)
                + m.encode_message(m.HelloAck(proto_version=1, firmware_id="t",
                                              capabilities=0), 1), at_us)


def _telemetry(app, at_us, servo1=1500):
    app.on_uart(m.encode_message(m.Telemetry(
        time_us=at_us, enc_left=0, enc_right=0, servo_us=(1000, servo1, 1500, 1500, 1500, 1500),
        sonar_mm=(m.SONAR_NO_ECHO,) * 5, flags=m.FLAG_HANDSHAKE, crc_errors=0, overruns=0,
        limit_hits=0, watchdog_trips=0), 2), at_us)


class _Task:
    """Needs both detectors, counts what it saw; some steps are long (a plan): they preempt
    vision, miss deadlines and skip ticks."""

    def __init__(self, heavy: dict[int, int], fallbacks: dict | None = None) -> None:
        self.heavy = heavy  # step index -> cycles
        self.fallbacks = fallbacks or {}
        self.seen: list = []

    def detectors_needed(self):
        return ["a", "b"]

    def detector_fallbacks(self):
        return self.fallbacks

    def step(self, now_us, inputs):
        k = len(self.seen)
        self.seen.append(sorted(inputs.items()))
        return FakeOutputs(servo_mrad=(0, 0, -1571, -1571, 1571, len(self.seen) % 7),
                           wheels_mmps=(k % 3, 0), state="SEARCH",
                           ops=OpCounts(alu=self.heavy.get(k, 4_000 * (k % 5))))


class _PoseDetector:
    """Reads the newest telemetry like dual_plus / double_cross do, through a snapshot."""

    def __init__(self, app_ref):
        self.app_ref = app_ref
        self.calls = 0

    def snapshot(self):
        tel = self.app_ref[0].link.telemetry
        return (None if tel is None else (tel.time_us, tel.servo_us[1]),)

    def __call__(self, rgb, pose):
        self.calls += 1
        return {"pose": pose}, OpCounts(alu=1_000_000 + 2_000_000 * (int(rgb[0, 0, 1]) % 3))


def _detector_a(rgb):
    # 10 ms + up to 25 ms by content: the bound below (10 ms) is its cost on a black frame
    return {"mean": int(rgb[..., 0].mean())}, OpCounts(alu=4_000_000 + 40_000 * int(rgb[0, 0, 0]))


def _detector_a_or_none(rgb):
    # _detector_a, finding nothing on frames of odd red
    res, ops = _detector_a(rgb)
    return (None if rgb[0, 0, 0] % 2 else res), ops


# both fakes start from one front end of 2 ms (within both bounds)
SHARED = {"a": ("fe", lambda h, w: 2_000), "b": ("fe", lambda h, w: 2_000)}


def _run(bounded: bool, seed: int, policy: str, shared: bool = False):
    """One second of frames, telemetry and ticks in 5 ms quanta like the lockstep client: UART
    bytes, then frames, then advance_to; after each quantum the detectors run as ``policy``
    says ("eager": always, today's client; "needed": only if the next tick may need them).
    ``shared``: the two detectors share a front end and "b" runs only when "a" finds nothing."""
    rng = np.random.default_rng(seed)
    heavy = {int(k): int(c) for k, c in zip(rng.integers(2, 45, 4),
                                            rng.integers(4_000_000, 22_000_000, 4), strict=True)}
    task = _Task(heavy, {"b": "a"} if shared else None)
    app_ref: list = []
    pose = _PoseDetector(app_ref)
    bounds = {"a": lambda h, w: 10_000, "b": lambda h, w: 2_500} if bounded else None
    app = HostApp(task, {"a": _detector_a_or_none if shared else _detector_a, "b": pose},
                  build_inputs, HostConfig(hello_wait_us=0), vision_bounds=bounds,
                  front_ends=SHARED if shared else None)
    app_ref.append(app)
    frames, t = [], 0
    while t < 1_000_000:
        t += int(rng.integers(1, 14)) * QUANTUM
        rgb = None if rng.random() < 0.1 else np.full((6, 8, 3), rng.integers(0, 256, 3),
                                                      np.uint8)
        frames.append((t, rgb))
    out = {"quanta": [], "loads": []}
    deferred = 0
    seq = 0
    for s in range(0, 1_000_000, QUANTUM):
        if s == 5_000:
            _ack_hello(app, s + 300)
        if s >= 5_000 and s % 10_000 == 5_000:
            _telemetry(app, s + 1_000, servo1=1000 + s // 1_000)  # pose changes every time
        for t_arr, rgb in frames:
            if t_arr == s:
                app.on_frame(seq, s - 2_000, s, rgb)
                seq += 1
        app.advance_to(s + QUANTUM)
        if (s + QUANTUM) % 500_000 == 0:
            out["loads"].append(app.load_windows())
        out["quanta"].append((app.take_events(), app.take_output(s + QUANTUM)))
        pending = app._vision is not None and app._vision.pending is not None
        if policy == "eager" or (policy == "needed" and app.vision_needed_by()):
            app.resolve_vision()
        elif pending:
            deferred += 1
    out["stats"] = app.stats()
    out["stage_us"] = app.counters.stage_us
    out["seen"] = task.seen
    return out, deferred, pose.calls


def test_deferred_detectors_change_nothing_modelled():
    skipped = 0
    for seed in range(6):
        want, _, calls = _run(False, seed, "eager")
        got, deferred, calls_b = _run(True, seed, "needed")
        assert deferred > 3  # ticks did pass while the job's detectors had not run
        assert calls_b == calls
        assert got == want, seed
        # the same without any early run at all: only ticks, frames and load windows force it
        late, _, _ = _run(True, seed, "never")
        assert late == want, seed
        assert want["stats"]["frames_dropped"] > 0 and want["stats"]["deadline_misses"] > 0
        skipped += want["stats"]["ticks_skipped"]
    assert skipped > 0


def test_shared_front_end_and_fallback_keep_the_bound_a_bound():
    for seed in range(4):
        want, _, calls = _run(False, seed, "eager", shared=True)
        got, deferred, calls_b = _run(True, seed, "needed", shared=True)
        assert deferred > 3 and calls_b == calls
        assert got == want, seed
        late, _, _ = _run(True, seed, "never", shared=True)
        assert late == want, seed
        # "b" ran on some frames only, and each time less the front end "a" computed
        alone, _, calls_alone = _run(False, seed, "eager")
        assert 0 < calls < calls_alone
        assert want["stage_us"]["b"].max_us < alone["stage_us"]["b"].max_us


def _one_frame_job(find_a: bool, shared: bool):
    """One frame given to "a" (10 ms + 0.1 ms per unit of red) and "b" (5 ms): the job's
    ARM9 µs, and which detectors ran; the job's end before they ran was a lower bound."""
    ran: list = []

    def a(rgb):
        ran.append("a")
        return ({"a": 1} if find_a else None), OpCounts(alu=4_000_000 + 40_000 * int(rgb[0, 0, 0]))

    def b(rgb):
        ran.append("b")
        return {"b": 1}, OpCounts(alu=2_000_000)

    task = _Task({}, {"b": "a"} if shared else None)
    app = HostApp(task, {"a": a, "b": b}, build_inputs, HostConfig(hello_wait_us=0),
                  vision_bounds={"a": lambda h, w: 10_000, "b": lambda h, w: 5_000},
                  front_ends=SHARED if shared else None)
    app.advance_to(1_000)
    app.on_frame(0, 0, 1_000, np.full((6, 8, 3), 10, np.uint8))
    app.advance_to(2_000)
    low = app._vision.done_us
    app.resolve_vision()
    assert ran and low <= app._vision.done_us
    return app._vision.arm9_us, ran


def test_a_shared_front_end_is_charged_once_and_a_fallback_runs_only_on_a_miss():
    overhead = HostConfig().frame_overhead_cycles // 400
    assert _one_frame_job(True, False) == (overhead + 11_000 + 5_000, ["a", "b"])
    # "a" found it: "b" does not run
    assert _one_frame_job(True, True) == (overhead + 11_000, ["a"])
    # "a" found nothing: "b" runs, less the front end "a" computed
    assert _one_frame_job(False, True) == (overhead + 11_000 + 5_000 - 2_000, ["a", "b"])


def test_unbounded_app_runs_the_detectors_at_every_question_as_before():
    calls = []

    def counting(rgb):
        calls.append(1)
        return blob_detector(4_000_000)(rgb)

    class T:
        def detectors_needed(self):
            return ["blob"]

        def detector_fallbacks(self):
            return {}

        def step(self, now_us, inputs):
            return FakeOutputs()

    app = HostApp(T(), {"blob": counting}, build_inputs, HostConfig(hello_wait_us=0))
    app.advance_to(20_000)
    app.on_frame(0, 19_000, 20_000, np.zeros((4, 4, 3), np.uint8))
    app.advance_to(25_000)
    assert app.vision_needed_by() and not calls  # no bound: the next tick needs them
    app.advance_to(45_000)  # the tick at 40 ms runs them
    assert calls == [1]


def test_a_tick_before_the_bound_leaves_the_detectors_pending():
    calls = []

    def counting(rgb):
        calls.append(1)
        return blob_detector(12_000_000)(rgb)  # 30 ms

    class T:
        def detectors_needed(self):
            return ["blob"]

        def detector_fallbacks(self):
            return {}

        def step(self, now_us, inputs):
            return FakeOutputs()

    app = HostApp(T(), {"blob": counting}, build_inputs, HostConfig(hello_wait_us=0),
                  vision_bounds={"blob": lambda h, w: 25_000})
    app.advance_to(15_000)
    app.on_frame(0, 14_000, 15_000, np.zeros((4, 4, 3), np.uint8))
    app.advance_to(20_000)
    # bounded end 15 ms + 50 us + 25 ms = 40.05 ms, after the tick at 20 ms; the tick's base
    # charge preempts it: after the tick at 40 ms too
    base_us = HostConfig().control_base_cycles // 400
    assert not app.vision_needed_by() and not calls
    app.advance_to(25_000)
    assert app._vision.done_us == 40_050 + base_us and not calls
    assert not app.vision_needed_by() and app.vision_needed_by(40_050 + base_us)
    app.advance_to(45_000)
    # preempted by the tick at 40 ms too: its base and 2 us for the bytes of the HELLO it resends
    assert calls == [] and app._vision.done_us == 40_050 + 2 * base_us + 2
    assert app.vision_needed_by()  # the tick at 60 ms may need it
    app.resolve_vision()
    assert calls == [1]
    # exact end: 15 ms + 50 us + 30 ms + the two ticks
    assert app._vision.done_us == 45_050 + 2 * base_us + 2
    assert app._vision.preempted_us == 2 * base_us + 2
    app.advance_to(65_000)
    assert app._vision is None
    assert [e["t_us"] for e in app.take_events() if e["ev"] == "detect"] == [
        45_050 + 2 * base_us + 2]


def test_pose_detector_of_the_factory_uses_the_snapshot():
    from mobigrasp.host.app_factory import _PoseDetector as Pose

    q_now = [(1, 2, 3, 4, 5, 6)]
    det = Pose(lambda rgb, q: (q, OpCounts()), lambda: q_now[0])
    snap = det.snapshot()
    q_now[0] = (9, 9, 9, 9, 9, 9)
    assert det(None, *snap)[0] == (1, 2, 3, 4, 5, 6)
    assert det(None)[0] == (9, 9, 9, 9, 9, 9)  # called without one: the pose now


def test_factory_gives_bounds_for_its_detectors():
    from mobigrasp.host.app_factory import build_host_app

    for method in ("000", "002"):
        app = build_host_app({"method": method})
        assert app.vision_bounds is not None
        assert set(app.vision_bounds) == set(app.detectors)
        for name, bound in app.vision_bounds.items():
            assert bound(240, 320) > 0, name
            assert bound(240, 320) == bound(240, 320)
        for name in ("dual_plus", "double_cross"):
            assert hasattr(app.detectors[name], "snapshot")


def test_a_job_whose_bound_is_its_end_is_finished_at_that_tick():
    # the bound equals the cost: the job ends exactly at the tick at 40 ms, which must see it
    class T:
        def __init__(self):
            self.inputs = []

        def detectors_needed(self):
            return ["blob"]

        def detector_fallbacks(self):
            return {}

        def step(self, now_us, inputs):
            self.inputs.append((now_us, sorted(inputs)))
            return FakeOutputs()

    def run(bounds, early=True):
        task = T()
        app = HostApp(task, {"blob": blob_detector(5_980_000)}, build_inputs,
                      HostConfig(hello_wait_us=0), vision_bounds=bounds)
        app.advance_to(5_000)
        _ack_hello(app, 5_000)
        for t in range(5_000, 60_000, 5_000):
            if t % 10_000 == 0:
                _telemetry(app, t)
            if t == 25_000:
                app.on_frame(0, 24_000, 25_000, np.zeros((4, 4, 3), np.uint8))
            app.advance_to(t + 5_000)
            if early and app.vision_needed_by():
                app.resolve_vision()
        return task.inputs, app.take_events()

    want = run(None)
    assert (40_000, ["blob"]) in want[0]
    assert [e["t_us"] for e in want[1] if e["ev"] == "detect"] == [40_000]
    bound = {"blob": lambda h, w: 14_950}  # 25 ms + 50 us + 14.95 ms = 40 ms
    assert run(bound) == want
    assert run(bound, early=False) == want  # the tick itself decides
