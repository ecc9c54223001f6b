"""HostApp on its own: handshake and retransmission, output validation, the ARM9 CPU model."""

import json
from dataclasses import dataclass

import numpy as np
from rig_fakes import FakeOutputs, FakeTask, blob_detector, build_inputs

from mobigrasp.host.app import HostApp, HostConfig, stage_summary
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.task import TaskEvent
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.frame import FrameParser


def _sent(app, until):
    parser = FrameParser()
    out = []
    for t, wire in app.take_output(until):
        for frame in parser.feed(wire):
            out.append((t, m.decode_frame(frame), frame.seq))
    return out


def _ack_hello(app, at_us):
    hello_seq = app.link._hello_seq
    app.on_uart(m.encode_message(m.Ack(acked_seq=hello_seq), 0)
                + m.encode_message(m.HelloAck(proto_version=1, firmware_id="t",
                                              capabilities=0), 1), at_us)


def _telemetry(app, at_us, flags=m.FLAG_HANDSHAKE, time_us=None):
    app.on_uart(m.encode_message(m.Telemetry(
        time_us=at_us if time_us is None else time_us, enc_left=0, enc_right=0,
        servo_us=(1000, 1500, 1500, 1500, 1500, 1500),
        sonar_mm=(m.SONAR_NO_ECHO,) * 5, flags=flags, crc_errors=0, overruns=0, limit_hits=0,
        watchdog_trips=0), 2), at_us)


def test_hello_is_retransmitted_until_acked_then_given_up():
    app = HostApp(FakeTask(), {}, build_inputs, HostConfig())
    app.advance_to(1_000_000)
    msgs = _sent(app, 1_000_000)
    hellos = [(t, seq) for t, msg, seq in msgs if isinstance(msg, m.Hello)]
    assert len(hellos) == 11  # first + 10 retries (RetransmitQueue max_retries)
    assert len({seq for _, seq in hellos}) == 1  # same seq every time
    assert all(b - a >= 40_000 for (a, _), (b, _) in zip(hellos, hellos[1:], strict=False))
    st = app.stats()["protocol"]
    assert st["retransmits"] == 10 and st["reliable_failed"] == 1
    assert app.counters.control_steps == 0  # the task never runs without a handshake


def test_first_hello_waits_until_the_mcu_is_heard_or_the_wait_is_over():
    # bytes sent into the MCU's start-up are lost: nothing leaves before its first telemetry
    app = HostApp(FakeTask(), {}, build_inputs, HostConfig())
    app.advance_to(30_000)
    assert _sent(app, 30_000) == []
    _telemetry(app, 35_000, flags=m.FLAG_RESET)
    app.advance_to(45_000)
    sent = _sent(app, 45_000)
    assert [t for t, msg, _ in sent if isinstance(msg, m.Hello)] == [40_000]
    # an MCU never heard (telemetry off) gets its HELLO at the first tick after the wait
    silent = HostApp(FakeTask(), {}, build_inputs, HostConfig())
    silent.advance_to(130_000)
    first = min(t for t, msg, _ in _sent(silent, 130_000) if isinstance(msg, m.Hello))
    assert first == HostConfig().hello_wait_us


class _BadTask(FakeTask):
    def __init__(self, servo, wheels):
        super().__init__()
        self.out = FakeOutputs(servo_mrad=servo, wheels_mmps=wheels, state="SEARCH")

    def step(self, now_us, inputs):
        return self.out


def _handshaken(task):
    # a host whose MCU is known to be up: HELLO at the first tick, without waiting to hear it
    app = HostApp(task, {}, build_inputs, HostConfig(hello_wait_us=0))
    app.advance_to(1)
    _ack_hello(app, 5_000)
    _telemetry(app, 6_000)
    app.advance_to(30_000)
    return app


def test_nan_servo_target_is_refused_and_wheels_clamped():
    app = _handshaken(_BadTask((0, 0, float("nan"), -1571, 1571, 0), (5000, -2000)))
    msgs = [msg for _, msg, _ in _sent(app, 30_000)]
    assert not any(isinstance(x, m.SetServos) for x in msgs)
    wheels = [x for x in msgs if isinstance(x, m.SetWheels)]
    assert wheels and (wheels[-1].left_mmps, wheels[-1].right_mmps) == (1000, -1000)
    st = app.stats()["protocol"]
    assert st["rejected_outputs"] >= 1 and st["clamped_outputs"] >= 1
    assert any(e["ev"] == "output_rejected" for e in app.take_events())


def test_servo_targets_are_clamped_to_joint_limits():
    app = _handshaken(_BadTask((0, 0, 500, -1571, 4000, 0), None))
    servos = [x for _, x, _ in _sent(app, 30_000) if isinstance(x, m.SetServos)]
    assert servos[-1].targets[2] == 0 and servos[-1].targets[4] == 3000  # conventions limits
    assert servos[-1].mode == m.SERVO_MODE_MRAD


def _frames_app(cost_alu):
    app = HostApp(FakeTask(), {"blob": blob_detector(cost_alu)}, build_inputs, HostConfig())
    rgb = np.zeros((4, 4, 3), np.uint8)
    for k in range(15):  # one second of frames at 15 fps, delivered at 5 ms quantum bounds
        cap = k * 1_000_000 // 15
        app.on_frame(k, cap, -(-cap // 5000) * 5000, rgb)
    app.advance_to(1_000_000)
    return app


def test_vision_slower_than_frame_period_drops_every_other_frame():
    fast = _frames_app(12_000_000)  # 30 ms per frame
    assert fast.counters.frames_dropped == 0 and fast.counters.frames_processed == 15
    slow = _frames_app(32_000_000)  # 80 ms per frame: each job spans the next arrival
    assert slow.counters.frames_processed == 8 and slow.counters.frames_dropped == 7
    loads = slow.load_windows()  # 500 ms windows: jobs of 80.05 ms started at 0, 133, 267, 400
    assert 4 * 80_050 / 500_000 <= loads[0] <= 4 * 80_050 / 500_000 + 0.01


def test_plan_in_a_control_step_misses_deadlines():
    class PlanTask(FakeTask):
        def step(self, now_us, inputs):
            out = super().step(now_us, inputs)
            out.ops = OpCounts(alu=20_000_000) if len(self.steps) == 3 else None  # 50 ms
            return out

    app = _handshaken(PlanTask())
    app.advance_to(200_000)
    assert app.counters.deadline_misses >= 2 and app.counters.ticks_skipped >= 1


def test_stage_summary_percentiles():
    s = stage_summary(list(range(1, 101)))
    assert (s["calls"], s["p95_us"], s["max_us"], s["mean_us"]) == (100, 95, 100, 50.5)
    assert stage_summary([])["calls"] == 0


def test_mcu_reset_seen_in_telemetry_reopens_the_session_and_resends_commands():
    app = _handshaken(_BadTask((0, 0, -1571, -1571, 1571, 0), (100, 100)))
    _sent(app, 30_000)
    _telemetry(app, 40_000, flags=m.FLAG_RESET, time_us=1_000)  # time went back, flag set
    app.advance_to(60_000)
    msgs = [msg for _, msg, _ in _sent(app, 60_000)]
    assert any(isinstance(x, m.Hello) for x in msgs)
    assert app.stats()["mcu_resets_seen"] == 1
    _ack_hello(app, 65_000)
    _telemetry(app, 66_000, time_us=2_000)
    app.advance_to(100_000)
    msgs = [msg for _, msg, _ in _sent(app, 100_000)]
    assert any(isinstance(x, m.SetServos) for x in msgs)  # the MCU forgot them: sent again


def test_newer_servo_command_supersedes_an_unanswered_one():
    class Moving(FakeTask):
        def step(self, now_us, inputs):
            return FakeOutputs(servo_mrad=(0, 0, -1571, -1571, 1571, now_us // 20_000),
                               state="SEARCH")

    app = _handshaken(Moving())
    app.advance_to(200_000)
    servos = [seq for _, x, seq in _sent(app, 200_000) if isinstance(x, m.SetServos)]
    assert len(servos) >= 5
    in_flight = app.link.reliable.in_flight()
    assert [s for s in servos if s in in_flight] == servos[-1:]  # only the newest is tracked


def test_detectors_run_late_but_their_results_and_timing_are_the_same():
    # A frame arriving after the tick of its quantum: the DONE of that quantum does not need the
    # detectors, so they run afterwards (resolve_vision) or at the next tick; either way the
    # modelled job, its events and the load are those of running them at once.
    def run(resolve_early: bool):
        calls = []
        detect = blob_detector(4_000_000)

        def counting(rgb):
            calls.append(1)
            return detect(rgb)

        task = FakeTask()
        task.detectors_needed = lambda: ["blob"]
        app = HostApp(task, {"blob": counting}, build_inputs, HostConfig())
        rgb = np.full((24, 32, 3), 77, np.uint8)
        app.advance_to(5_000)
        app.on_frame(0, 1_000, 5_000, rgb)
        app.advance_to(10_000)  # a quantum with the frame and no tick
        ran_before_done = len(calls)
        if resolve_early:
            app.resolve_vision()
        ran_after_done = len(calls)
        app.advance_to(60_000)  # two ticks later
        return ran_before_done, ran_after_done, app.take_events(), app.load_windows(), \
            app.stats()["stages"].get("blob")

    late, early = run(False), run(True)
    assert late[:2] == (0, 0) and early[:2] == (0, 1)
    assert late[2] == early[2] and late[3] == early[3] and late[4] == early[4]
    assert late[4]["calls"] == 1 and late[4]["total_us"] == 10_000
    assert any(e["ev"] == "detect" and e["results"]["blob"]["mean"] == 77 for e in late[2])


@dataclass
class _Found:
    centre: tuple
    score: float


def test_events_are_plain_json_as_taken():
    # The lockstep client sends take_events() as it is (no second jsonable pass): every event
    # must already be what the JSON codec gives back, whatever the task and detectors return
    # (tuples, dataclasses, numpy scalars, non-finite floats).
    class _Task(FakeTask):
        def step(self, now_us, inputs):
            out = super().step(now_us, inputs)
            out.events.append(TaskEvent(now_us, "SEARCH", "SEARCH", "again"))
            out.detail = {"plan": (1, 2), "gain": np.float64(0.5), "bad": float("nan"),
                          3: _Found((np.int32(4), 5), float("inf"))}
            out.servo_mrad = (0, 0, float("nan"), 0, 0, 0) if now_us == 40_000 else out.servo_mrad
            return out

    def detect(rgb):
        return _Found((np.int64(7), 8), 0.25), OpCounts(alu=400_000)

    task = _Task()
    app = HostApp(task, {"blob": detect}, build_inputs, HostConfig(hello_wait_us=0))
    app.advance_to(1)
    _ack_hello(app, 5_000)
    _telemetry(app, 6_000)
    rgb = np.zeros((4, 4, 3), np.uint8)
    for k in range(4):
        app.on_frame(k, k * 30_000, k * 30_000 + 1_000, rgb)
    app.advance_to(200_000)
    events = app.take_events()
    kinds = {e["ev"] for e in events}
    assert {"hello_ack", "detect", "state", "detail", "wheels", "output_rejected"} <= kinds
    for ev in events:
        assert json.loads(json.dumps(ev, allow_nan=False)) == ev


def test_a_step_handed_a_vision_job_s_results_is_charged_the_handover_too():
    """A control step is charged its base; the one that hands the task a finished vision job's
    results also the handover (docs/budget.md, "The control step's charge")."""
    cfg = HostConfig(hello_wait_us=0)
    app = HostApp(FakeTask(), {"blob": blob_detector(400_000)}, build_inputs, cfg)  # 1 ms
    app.advance_to(1)
    _ack_hello(app, 5_000)
    _telemetry(app, 6_000)
    app.advance_to(30_000)
    before = app.stats()["stages"]["control"]
    app.on_frame(0, 30_000, 30_000, np.zeros((4, 4, 3), np.uint8))
    app.advance_to(100_000)  # the job ends at 31.05 ms: the tick at 40 ms takes it over
    after = app.stats()["stages"]["control"]
    base_us, handover_us = cfg.control_base_cycles // 400, cfg.handover_cycles // 400
    assert after["calls"] - before["calls"] == 3  # the ticks at 40, 60 and 80 ms
    assert after["total_us"] - before["total_us"] == 3 * base_us + handover_us
    assert after["max_us"] == base_us + handover_us
    assert [e["t_us"] for e in app.take_events() if e["ev"] == "detect"] == [31_050]
