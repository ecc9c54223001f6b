"""The S3C2440 host program: control loop, vision scheduling and the ARM9 time budget.

One ARM920T core at 400 MHz runs two activities (docs/cosim.md, "ARM9 budget"):

- **control** (high priority, every ``control_period_us`` = 20 ms): read the newest telemetry,
  step the task (:class:`mobigrasp.host.task.Task`), send its outputs. Its modelled cost is a fixed
  per-step cost plus the protocol bytes handled plus whatever the task reports (a Bezier plan
  is charged at soft-float cost). If the step finishes after its deadline (the next tick) a
  deadline miss is counted; a tick that falls entirely inside a busy step is skipped and counted.
- **vision** (low priority, preempted by control): when a camera frame arrives and vision is idle,
  the detectors the task needs now (``Task.detectors_needed()``) run on it; their OpCounts give
  the modelled time, stretched by any control step that preempts it. A frame that arrives while
  vision is still busy is dropped and counted, as on the board. Results reach the task at the
  first control tick after vision finishes. Detectors of one frame that start from the same
  front end (the grey image, dark mask and components of the 000 detectors) share it: the
  first pays for it. A fallback detector (``Task.detector_fallbacks()``) runs only when the
  detector it stands in for found nothing on the frame (docs/budget.md).

Host load is the modelled busy time per ``load_window_us`` window. The Python wall time is never
read here (host/ has no wall clock): the profiler wraps stages through the ``timer`` hook.
Time only moves through :meth:`HostApp.advance_to` and the arrival times given with data.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from mobigrasp.host.app_link import HostLink
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.stage_stats import StageStats, micro_ratio

Detector = Callable[..., tuple[Any, OpCounts]]
# ARM9 load windows kept one by one (32 s of 500 ms windows: a vision job ends long before its
# window leaves them); older ones live on only in the run's count, sum and maximum of load
LOAD_WINDOWS_KEPT = 64
# a detector's lower bound of its modelled time (µs) on any frame of (height, width)
CostBound = Callable[[int, int], int]
# the front end a detector starts from: (its name, its modelled µs on a frame of (height,
# width)); the detector's own counts include it
FrontEnd = tuple[str, Callable[[int, int], int]]


@dataclass(frozen=True)
class HostConfig:
    """Timing and cost parameters of the host program (integer µs / ARM9 cycles)."""

    control_period_us: int = 20_000
    heartbeat_period_us: int = 100_000
    # The first HELLO (and heartbeat) waits until the MCU has been heard (its telemetry: it is
    # listening), at most this long after the first tick: bytes sent into the MCU's start-up
    # are lost (docs/firmware.md, "simavr")
    hello_wait_us: int = 100_000
    wheels_repeat_us: int = 100_000  # SetWheels is unreliable: repeat the last one this often
    load_window_us: int = 500_000
    # a control step with nothing new: telemetry parsed and decoded, the task's inputs, its step,
    # the commands, the bookkeeping: 55 µs, and a step that takes over a finished vision job's
    # results also its detect event and the results handed to the task: 30 µs (the C program's
    # steps as ARM920T code, docs/budget.md "Whole control steps and frame pipelines")
    control_base_cycles: int = 22_000
    handover_cycles: int = 12_000
    protocol_cycles_per_byte: int = 40  # COBS + CRC-16 + copy, both directions
    frame_overhead_cycles: int = 20_000  # CAMIF buffer hand-over, cache maintenance: 50 µs
    servo_slew_mrad_s: int = 0


def jsonable(obj: Any) -> Any:
    """Plain JSON data from task/detector results: dataclasses, tuples, numpy, non-finite floats."""
    # fast paths by exact type (the answer depends only on the type for these): plain ints and
    # strings, plain dicts/lists/tuples, and dataclasses met before (their field names cached)
    t = type(obj)
    if t is int or t is str or obj is None:
        return obj
    if t is dict:
        return {str(k): jsonable(v) for k, v in obj.items()}
    if t is list or t is tuple:
        return [jsonable(v) for v in obj]
    names = _DATACLASS_FIELDS.get(t)
    if names is not None:
        return {n: jsonable(getattr(obj, n)) for n in names}
    if obj is None or isinstance(obj, bool | int | str):
        return obj
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, OpCounts):
        return {"arm9_us": obj.time_us()}
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        names = tuple(f.name for f in dataclasses.fields(obj))
        _DATACLASS_FIELDS[t] = names
        return {n: jsonable(getattr(obj, n)) for n in names}
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, set | frozenset):  # sorted: set order of strings varies per process
        return sorted((jsonable(v) for v in obj), key=repr)
    if isinstance(obj, list | tuple):
        return [jsonable(v) for v in obj]
    if hasattr(obj, "tolist"):  # numpy arrays and scalars
        return jsonable(obj.tolist())
    return str(obj)


_DATACLASS_FIELDS: dict[type, tuple[str, ...]] = {}  # dataclass type -> field names (jsonable)


@dataclass
class _VisionJob:
    seq: int
    capture_us: int
    start_us: int
    done_us: int
    results: dict
    arm9_us: int
    # (detector names, rgb, snapshots, fallbacks) while the detectors have not run yet: they
    # run when something needs the job's results or length (resolve_vision), which changes
    # nothing that is modelled. Meanwhile done_us is a lower bound of the job's end (bounded)
    # or start + frame overhead (not bounded: every question about the end resolves the job
    # first).
    pending: tuple | None = None
    bounded: bool = False
    preempted_us: int = 0  # control preemption added to done_us so far


class _SharedFrontEnds:
    """The front ends computed so far on one frame: a detector's modelled µs less its front
    end's when an earlier detector of the frame computed the same one."""

    def __init__(self, front_ends: dict[str, FrontEnd], rgb: Any) -> None:
        self._front_ends = front_ends
        self._rgb = rgb
        self._done: set[str] = set()

    def charge(self, name: str, us: int) -> int:
        fe = self._front_ends.get(name)
        if fe is None:
            return us
        if fe[0] in self._done:
            return max(0, us - fe[1](self._rgb.shape[0], self._rgb.shape[1]))
        self._done.add(fe[0])
        return us


@dataclass
class HostCounters:
    """Budget figures of the run: frames_*, deadline_misses, load (docs/cosim.md, "The ARM9
    budget")."""

    frames_received: int = 0
    frames_processed: int = 0
    frames_dropped: int = 0
    frames_idle: int = 0  # arrived while idle but the task needed no detector
    control_steps: int = 0
    deadline_misses: int = 0
    ticks_skipped: int = 0
    stage_us: dict = field(default_factory=dict)  # stage -> StageStats of its modelled µs


class HostApp:
    """The host program, driven in simulated time by a lockstep client or a real-board loop.

    ``task`` has ``step(now_us, inputs) -> outputs`` and ``detectors_needed() -> list[str]``;
    ``build_inputs(app, now_us, detections) -> inputs`` turns what the host knows (telemetry in
    ``app.link.telemetry``) into the task's inputs; ``detectors`` maps names to
    ``detect(rgb) -> (result | None, OpCounts)``; ``timer(stage, fn, *args)`` calls ``fn`` and
    may measure it (the profiler's wall-clock hook; the default just calls).

    A detector with a ``snapshot()`` method (one that reads the arm pose) is asked for it when
    its frame's job is created and is called as ``detect(rgb, *snapshot)``, so it gives the same
    result whenever its job runs. ``vision_bounds`` maps detector names to
    ``bound(height, width) -> µs``, a proven lower bound of the detector's modelled time on any
    frame of that size: a job whose bounded end lies after a tick or frame certainly has not
    ended there, and its detectors may run later. Without it (the default) every such question
    runs the detectors first. ``front_ends`` maps detector names to their :data:`FrontEnd`: of
    the detectors of one frame with the same front end, the first is charged all its counts,
    the others their counts less the front end's (on the board it is computed once a frame).

    ``task.detector_fallbacks() -> {name: primary}`` names the detectors of
    ``detectors_needed()`` that run on a frame only when ``primary`` (listed before them) found
    nothing on it.

    ``recorder(kind, *args)`` (optional) is told the program's inputs and outputs as they pass
    its interface, so a run can be replayed on another build of the program (calib/program.py):
    ``("uart", data, arrival_us)``, ``("frame", seq, capture_us, arrival_us, rgb)``,
    ``("advance", until_us)``, ``("output", chunks)`` (take_output's) and ``("events",
    events)`` (take_events'). It must not change what it is given.
    """

    def __init__(self, task: Any, detectors: dict[str, Detector],
                 build_inputs: Callable[[HostApp, int, dict], Any],
                 config: HostConfig | None = None, link: HostLink | None = None,
                 timer: Callable[..., Any] | None = None,
                 vision_bounds: dict[str, CostBound] | None = None,
                 front_ends: dict[str, FrontEnd] | None = None,
                 recorder: Callable[..., None] | None = None) -> None:
        self.task = task
        self.recorder = recorder
        self.detectors = detectors
        self.vision_bounds = vision_bounds
        self.front_ends = front_ends or {}
        self.build_inputs = build_inputs
        self.config = config or HostConfig()
        self.link = link or HostLink()
        self.timer = timer or (lambda stage, fn, *a: fn(*a))
        self.counters = HostCounters()
        self.now_us = 0
        self.state = "INIT"
        self.finished = False
        self._next_tick_us = 0
        self._ctrl_free_us = 0
        self._vision: _VisionJob | None = None
        self._detections: dict = {}
        self.last_frame: dict = {}
        self._frames: list[tuple[int, int, int, Any]] = []  # (arrival_us, seq, capture_us, rgb)
        self._events: list[dict] = []
        # window index -> busy µs, for the last LOAD_WINDOWS_KEPT windows; older windows are
        # folded into the running figures below (the run's state stays bounded)
        self._load: dict[int, int] = {}
        self._load_folded = (0, 0, 0)  # windows folded: count, sum and max of their busy µs
        self._last = {"servos": None, "wheels": None, "gripper": None}
        self._last_wheels_us = -(10**12)
        self._last_heartbeat_us = -(10**12)
        self._hello_sent = False
        self._first_tick_us: int | None = None
        self._resets_handled = 0
        self.replans = 0
        self.plans = 0
        self.path_updates = 0  # a new curve adopted while one was followed (docs/task.md)
        self.close_reason: str | None = None  # the last grasp_close of the trace
        self.circle_error_mm: int | None = None  # 001: the first arrival on the grasp circle

    # ---- inputs from the driver --------------------------------------------------------------
    def on_uart(self, data: bytes, arrival_us: int) -> None:
        """Serial bytes that arrived at ``arrival_us`` (parsed now, used at the next tick)."""
        if self.recorder is not None:
            self.recorder("uart", data, arrival_us)
        self.link.receive(data, arrival_us)

    def on_frame(self, seq: int, capture_us: int, arrival_us: int, rgb: Any) -> None:
        """A camera frame the CAMIF delivered at ``arrival_us`` (handled in time order)."""
        if self.recorder is not None:
            self.recorder("frame", seq, capture_us, arrival_us, rgb)
        self._frames.append((arrival_us, seq, capture_us, rgb))

    # ---- time -------------------------------------------------------------------------------
    def advance_to(self, until_us: int) -> None:
        """Run everything due before ``until_us``; never acts at or beyond it."""
        if until_us < self.now_us:
            raise ValueError(f"cannot run back from {self.now_us} to {until_us} us")
        if self.recorder is not None:
            self.recorder("advance", until_us)
        if len(self._frames) > 1:
            self._frames.sort(key=lambda f: (f[0], f[1]))
        while True:
            t_frame = self._frames[0][0] if self._frames else None
            t_tick = self._next_tick_us
            if t_tick < until_us and (t_frame is None or t_tick <= t_frame):
                self._tick(t_tick)
                self._next_tick_us += self.config.control_period_us
            elif t_frame is not None and t_frame < until_us:
                arrival, seq, capture_us, rgb = self._frames.pop(0)
                self._frame(arrival, seq, capture_us, rgb)
            else:
                break
        self.now_us = until_us

    def wants_frames(self) -> bool:
        """Whether the task needs any detector now (the camera can be off otherwise)."""
        # asked once per served grant: the set test in C instead of a generator
        return not self.detectors.keys().isdisjoint(self.task.detectors_needed())

    def quiet_until_us(self) -> int:
        """The program writes nothing and changes no state, task or camera wish before this
        time unless a control tick comes first: the next tick, or the send time of the first
        byte still queued if earlier. Received bytes and frames only feed the parser and
        vision (trace events, load), so a quantum ending at or before it that brings only
        those is answered without bytes and with the same state (docs/cosim.md, pipelining)."""
        nxt = self.link.next_send_us()
        return self._next_tick_us if nxt is None else min(self._next_tick_us, nxt)

    def take_output(self, before_us: int) -> list[tuple[int, bytes]]:
        """Wire chunks to write to the serial port, with their send times (< before_us)."""
        out = self.link.take_output(before_us)
        if self.recorder is not None:
            self.recorder("output", out)
        return out

    def take_events(self) -> list[dict]:
        """Trace events since the last call (simulated-time data only), plain JSON data: every
        event is built from ints, strings, bools and :func:`jsonable` values, so the lockstep
        client sends them as they are (tests/test_rig_host_app.py checks the round trip)."""
        if not self._events and not self.link.events:
            return []
        out = self._events + self.link.events
        self._events, self.link.events = [], []
        if self.recorder is not None:
            self.recorder("events", out)
        return out

    def vision_needed_by(self, t_us: int | None = None) -> bool:
        """Whether a job whose detectors have not run yet might have ended by ``t_us`` (default:
        the start of the next control tick), so that its detectors must run before then. False
        when the job's lower-bounded end lies after it, or there is no such job."""
        job = self._vision
        if job is None or job.pending is None:
            return False
        if t_us is None:
            t_us = max(self._next_tick_us, self._ctrl_free_us)
        return not job.bounded or job.done_us <= t_us

    def load_windows(self) -> dict[int, float]:
        """Modelled ARM9 load (busy fraction) of each window that has finished."""
        self.resolve_vision()
        w = self.config.load_window_us
        done = self.now_us // w
        return {k: v / w for k, v in sorted(self._load.items()) if k < done}

    def _fold_old_loads(self, newest: int) -> None:
        """Fold the windows more than LOAD_WINDOWS_KEPT before window ``newest`` into the
        running count, sum and max (in window order, so the sums are those of the whole list)."""
        limit = newest - LOAD_WINDOWS_KEPT
        n, total, peak = self._load_folded
        for k in sorted(k for k in self._load if k < limit):
            busy = self._load.pop(k)
            n, total, peak = n + 1, total + busy, max(peak, busy)
        self._load_folded = (n, total, peak)

    # ---- the two activities -----------------------------------------------------------------
    def _busy(self, start_us: int, dur_us: int, stage: str) -> None:
        stats = self.counters.stage_us.get(stage)
        if stats is None:
            stats = self.counters.stage_us[stage] = StageStats()
        stats.add(dur_us)
        w = self.config.load_window_us
        t, end = start_us, start_us + dur_us
        while t < end:
            k = t // w
            seg = min(end, (k + 1) * w) - t
            if k in self._load:
                self._load[k] += seg
            else:  # a new window: the oldest kept ones are folded
                self._load[k] = seg
                if len(self._load) > LOAD_WINDOWS_KEPT:
                    self._fold_old_loads(k)
            t += seg

    def _frame(self, arrival_us: int, seq: int, capture_us: int, rgb: Any) -> None:
        c = self.counters
        c.frames_received += 1
        # a pending job is resolved even when its bound says the frame is dropped: the event
        # carries the job's exact end
        self.resolve_vision()
        if self._vision is not None and self._vision.done_us > arrival_us:
            c.frames_dropped += 1
            self._events.append({"ev": "frame_dropped", "t_us": arrival_us, "seq": seq,
                                 "busy_until_us": self._vision.done_us})
            return
        self._finish_vision(arrival_us)
        needed = [n for n in self.task.detectors_needed() if n in self.detectors]
        if not needed or rgb is None:  # nothing to look for, or the camera was off
            c.frames_idle += 1
            return
        start = max(arrival_us, self._ctrl_free_us)
        total = self.config.frame_overhead_cycles * 1_000_000 // 400_000_000
        self._busy(start, total, "frame")
        c.frames_processed += 1
        # what the pose-reading detectors read, taken now: the newest telemetry when the frame
        # is handed over (all UART bytes of a quantum are fed before its frames are handled)
        snaps = []
        for n in needed:
            snap = getattr(self.detectors[n], "snapshot", None)
            snaps.append(() if snap is None else tuple(snap()))
        fallbacks = self.task.detector_fallbacks()
        bounds = self.vision_bounds
        low = total
        if bounds is not None and getattr(rgb, "ndim", 0) == 3:  # else the detectors raise
            # the detectors that run whatever the others find, each less a front end shared
            # with one before it (a fallback may not run: it adds nothing to the bound)
            shared = _SharedFrontEnds(self.front_ends, rgb)
            low += sum(shared.charge(n, bounds[n](rgb.shape[0], rgb.shape[1]))
                       for n in needed if n in bounds and n not in fallbacks)
        self._vision = _VisionJob(seq, capture_us, start, start + low, {}, total,
                                  pending=(needed, rgb, snaps, fallbacks),
                                  bounded=bounds is not None)

    def resolve_vision(self) -> None:
        """Run the detectors of the current vision job if they have not run yet.

        A job's results and length are first needed at the next frame, at the first control
        tick its lower-bounded end does not lie after (all of them without ``vision_bounds``),
        or by a finished load window; until then the detectors may wait. The lockstep client
        runs them right after the DONE of the quantum the frame arrived in
        (LockstepClient.after_done; waiting longer, as :meth:`vision_needed_by` would allow,
        was measured no faster). Nothing modelled depends on when this runs: the pose the
        detectors read was taken when the frame arrived (``snapshot``)."""
        job = self._vision
        if job is None or job.pending is None:
            return
        needed, rgb, snaps, fallbacks = job.pending
        job.pending = None
        total = job.arm9_us
        shared = _SharedFrontEnds(self.front_ends, rgb)
        for name, snap in zip(needed, snaps, strict=True):
            primary = fallbacks.get(name)
            if primary is not None and job.results.get(primary) is not None:
                continue  # what it stands in for was found on this frame
            result, ops = self.timer(name, self.detectors[name], rgb, *snap)
            dur = shared.charge(name, ops.time_us())
            self._busy(job.start_us + total, dur, name)
            total += dur
            job.results[name] = result
        job.arm9_us = total
        job.done_us = job.start_us + total + job.preempted_us

    def _finish_vision(self, now_us: int) -> None:
        job = self._vision
        if job is None:
            return
        if job.pending is not None:
            if job.bounded and job.done_us > now_us:
                return  # even its lower bound ends later: not finished, the detectors may wait
            self.resolve_vision()
        if job.done_us > now_us:
            return
        self._vision = None
        self._detections = dict(job.results)
        self.last_frame = {"seq": job.seq, "capture_us": job.capture_us, "done_us": job.done_us}
        self._events.append({"ev": "detect", "t_us": job.done_us, "seq": job.seq,
                             "capture_us": job.capture_us, "arm9_us": job.arm9_us,
                             "results": jsonable(job.results)})

    def _tick(self, t_us: int) -> None:
        cfg, c = self.config, self.counters
        if self._ctrl_free_us >= t_us + cfg.control_period_us:
            c.ticks_skipped += 1
            c.deadline_misses += 1
            self._events.append({"ev": "deadline_miss", "t_us": t_us, "skipped": True})
            return
        start = max(t_us, self._ctrl_free_us)
        self._finish_vision(start)
        link = self.link
        tx_before = link.counters.tx_bytes
        link.service(start)
        if self._first_tick_us is None:
            self._first_tick_us = start
        first = not self._hello_sent and (link.telemetry is not None
                                          or start - self._first_tick_us >= cfg.hello_wait_us)
        if first or (self._hello_sent and link.mcu_resets > self._resets_handled
                     and link.needs_hello):
            link.hello(start)  # first session, or again after the MCU reset
            self._hello_sent = True
            self._resets_handled = link.mcu_resets
            self._last = {"servos": None, "wheels": None, "gripper": None}  # resend all
        cycles = cfg.control_base_cycles
        if link.handshake_ok and link.telemetry is not None and not self.finished:
            detections, self._detections = self._detections, {}
            if detections:  # a finished vision job's results handed to the task
                cycles += cfg.handover_cycles
            inputs = self.build_inputs(self, start, detections)
            out = self.timer("task", self.task.step, start, inputs)
            c.control_steps += 1
            ops = getattr(out, "ops", None)
            task_us = ops.time_us() if isinstance(ops, OpCounts) else 0
            ctrl_us = cycles * 1_000_000 // 400_000_000 + task_us
            done = start + ctrl_us
            self._apply(out, done)
        else:
            done = start + cycles * 1_000_000 // 400_000_000
        if self._hello_sent and done - self._last_heartbeat_us >= cfg.heartbeat_period_us:
            link.send_heartbeat(done)
            self._last_heartbeat_us = done
        proto_bytes = link.rx_bytes_since_take + link.counters.tx_bytes - tx_before
        link.rx_bytes_since_take = 0
        proto_us = proto_bytes * cfg.protocol_cycles_per_byte * 1_000_000 // 400_000_000
        self._busy(start, done - start, "control")
        self._busy(done, proto_us, "protocol")
        done += proto_us
        if done > t_us + cfg.control_period_us:
            c.deadline_misses += 1
            self._events.append({"ev": "deadline_miss", "t_us": t_us, "done_us": done})
        job = self._vision
        # a job still pending here has a lower bound of its end > start (_finish_vision), so
        # the test gives what the exact end would
        if job is not None and job.start_us < done and job.done_us > start:
            job.done_us += done - start  # control preempted vision for that long
            job.preempted_us += done - start
        self._ctrl_free_us = done

    def _apply(self, out: Any, at_us: int) -> None:
        link, last = self.link, self._last
        for ev in getattr(out, "events", None) or []:
            d = jsonable(ev)
            if "to_state" in d:  # host.task.TaskEvent
                d = {"t_us": d["t_us"], "from": d["from_state"], "to": d["to_state"],
                     "why": d.get("why", "")}
            self._events.append({"ev": "state", **d})
        state = getattr(out, "state", None)
        if state is not None and state != self.state:
            self.state = str(state)
        detail = getattr(out, "detail", None)
        if detail:
            if detail.get("plan") is not None:
                self.plans += 1  # every plan after the first one is a replan (001 §III.E)
                self.replans = max(0, self.plans - 1)
                if detail.get("replan") is not None:
                    self.path_updates += 1
            if detail.get("grasp_close") is not None:
                self.close_reason = str(detail["grasp_close"])
            circle = detail.get("grasp_circle")
            if isinstance(circle, dict) and self.circle_error_mm is None:
                self.circle_error_mm = int(circle["error_mm"])
            self._events.append({"ev": "detail", "t_us": at_us, "state": self.state,
                                 **jsonable(detail)})
        servos = getattr(out, "servo_mrad", None)
        if servos is not None and tuple(servos) != last["servos"]:
            if link.send_servos_mrad(tuple(servos), at_us, self.config.servo_slew_mrad_s):
                last["servos"] = tuple(servos)
        gripper = getattr(out, "gripper_permille", None)
        if gripper is not None and gripper != last["gripper"]:
            if link.send_gripper(gripper, at_us):
                last["gripper"] = gripper
        wheels = getattr(out, "wheels_mmps", None)
        if wheels is None:
            wheels = last["wheels"]
        if wheels is not None and (tuple(wheels) != last["wheels"]
                                   or at_us - self._last_wheels_us >= self.config.wheels_repeat_us):
            if link.send_wheels(wheels[0], wheels[1], at_us):
                if tuple(wheels) != last["wheels"]:
                    self._events.append({"ev": "wheels", "t_us": at_us,
                                         "mmps": jsonable(list(wheels))})
                last["wheels"] = tuple(wheels)
                self._last_wheels_us = at_us
        if self.state in ("DONE", "FAILED"):
            self.finished = True

    def stats(self) -> dict:
        """Final figures: budget counters, stage costs, load and the protocol counters."""
        c = self.counters
        self.resolve_vision()
        w = self.config.load_window_us
        n, total, peak = self._load_folded
        for k, busy in self._load.items():  # the finished windows kept, after the folded ones
            if k < self.now_us // w:
                n, total, peak = n + 1, total + busy, max(peak, busy)
        return {
            "frames_received": c.frames_received, "frames_processed": c.frames_processed,
            "frames_dropped": c.frames_dropped, "frames_idle": c.frames_idle,
            "control_steps": c.control_steps, "deadline_misses": c.deadline_misses,
            "ticks_skipped": c.ticks_skipped,
            # busy fractions to the millionth, integer ratios (the C host prints them alike)
            "arm9_load_max": micro_ratio(peak, w),
            "arm9_load_mean": micro_ratio(total, n * w) if n else 0.0,
            "stages": {k: v.summary() for k, v in sorted(c.stage_us.items())},
            "protocol": self.link.stats(), "state": self.state, "mcu": self._mcu_counters(),
            "replans": self.replans, "path_updates": self.path_updates,
            "close_reason": self.close_reason, "circle_error_mm": self.circle_error_mm,
            "mcu_resets_seen": self.link.mcu_resets,
        }

    def _mcu_counters(self) -> dict:
        tel = self.link.telemetry
        if tel is None:
            return {}
        return {"crc_errors": tel.crc_errors, "overruns": tel.overruns,
                "limit_hits": tel.limit_hits, "watchdog_trips": tel.watchdog_trips}


def stage_summary(values: list[int]) -> dict:
    """calls, mean, p95 (nearest rank), max and total of modelled µs per call."""
    if not values:
        return {"calls": 0, "mean_us": 0.0, "p95_us": 0, "max_us": 0, "total_us": 0}
    s = sorted(values)
    p95 = s[min(len(s) - 1, max(0, -(-95 * len(s) // 100) - 1))]
    return {"calls": len(s), "mean_us": micro_ratio(sum(s), len(s)), "p95_us": p95, "max_us": s[-1],
            "total_us": sum(s)}
