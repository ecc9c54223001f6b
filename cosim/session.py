"""The session engine: the rig's lockstep loop against a host end until the task ends.

The SIM side (this process) owns simulated time: it grants quanta to the host, writes the trace,
samples ground truth and paces to wall time when asked (``speed``; pacing never changes what is
simulated). The host end is a :class:`mobigrasp.cosim.handshake.HostEnd`.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.handshake import HostEnd, PendingDone, needed, resolved

TERMINAL_STATES = ("DONE", "FAILED")


@dataclass
class SessionResult:
    """What the loop knows at its end (also when it ended by an exception)."""

    reason: str = "running"
    end_us: int = 0
    wall_s: float = 0.0
    host_state: str = "INIT"
    host_finished: bool = False
    host_stats: dict = field(default_factory=dict)
    state_enter_us: dict = field(default_factory=dict)
    state_durations_us: dict = field(default_factory=dict)
    error: str | None = None


def run_session(rig: Any, host: HostEnd, trace: Any, *, time_limit_us: int,
                truth: Callable[[int], dict] | None = None, truth_period_us: int = 100_000,
                on_host_event: Callable[[dict], None] | None = None,
                on_quantum: Callable[[int], None] | None = None,
                speed: float | None = None, settle_us: int = 500_000,
                progress: Callable[[SessionResult, float], None] | None = None,
                stop: Callable[[], str | None] | None = None,
                result: SessionResult | None = None) -> SessionResult:
    """Run quanta until the host's task ends (plus ``settle_us``), ``stop()`` says so, or the
    time limit. ``speed`` = None runs as fast as possible, else sim/wall = speed (pacing only).
    ``result`` is filled in place, so a caller still has it when the loop raises."""
    res = result if result is not None else SessionResult()
    wall0 = time.perf_counter()
    next_truth = 0
    next_progress = 0.0
    finished_at: int | None = None
    state_since = 0
    # Trace work in quantum order: a PendingDone (pipelined grant) holds back what follows it
    # until its real DONE is read, so the trace is the same as answered one by one.
    backlog: deque[tuple[str, Any]] = deque()
    inflight: deque[ls.Done] = deque()  # DONEs of grants issued, for quanta not completed yet
    submit, early_wanted = host.submit, host.early_wanted  # bound once: called every quantum

    def handle(done: ls.Done) -> None:
        nonlocal state_since, finished_at
        for ev in done.events:
            trace.write({"src": "host", **ev})
            if ev.get("ev") == "state" and "to" in ev:
                frm = str(ev.get("from", res.host_state))
                res.state_durations_us[frm] = (res.state_durations_us.get(frm, 0)
                                               + ev["t_us"] - state_since)
                state_since = ev["t_us"]
                res.state_enter_us.setdefault(str(ev["to"]), ev["t_us"])
                res.host_state = str(ev["to"])
            if on_host_event is not None:
                on_host_event(ev)
        windows = done.load.get("windows")
        if windows:  # at most one quantum per load window has them
            for k, v in sorted(windows.items(), key=lambda i: int(i[0])):
                trace.write({"ev": "load", "t_us": int(k) * done.load["window_us"],
                             "window_us": done.load["window_us"], "load": v})
        res.host_state = str(done.load.get("state", res.host_state))
        if done.load.get("finished") and finished_at is None:
            finished_at = done.until_us
            res.host_finished = True

    def drain(block: bool) -> None:
        while backlog:
            kind, item = backlog[0]
            if kind == "line":
                trace.write(item)
            else:
                real = resolved(item, block)
                if real is None:
                    return
                handle(real)
            backlog.popleft()

    try:
        while True:
            now = rig.now_us
            if truth is not None and now >= next_truth:
                backlog.append(("line", {"ev": "truth", "t_us": now, **truth(now)}))
                drain(block=False)
                next_truth += truth_period_us
            # a pending DONE never changes finished or state (SocketHost checks the promise)
            if finished_at is not None and now >= finished_at + settle_us:
                res.reason = "task_" + res.host_state.lower()
                break
            if now >= time_limit_us:
                res.reason = "time_limit"
                break
            if stop is not None and (why := stop()):
                res.reason = why
                break
            # the DONE of [now, now+Q) (its grant first if not issued yet), then the grants up to
            # now + (1 + host_lag_quanta) quanta, or one more when it would be the same later
            # (Rig.grants_due): issued after that DONE was read, they are more often covered by
            # its quiet_until (so not sent, or sent in one batch); the grants hold only what the
            # MCU and camera produced before now either way
            if not inflight:
                inflight.append(submit(rig.grant()))
            done = needed(inflight.popleft())
            # (asked again while it says more: a grant two quanta early needs the DONE of the
            # one before it, issued by the previous round)
            while due := rig.grants_due(done, early_wanted, inflight):
                for _ in range(due):
                    inflight.append(submit(rig.grant()))
            backlog.append(("done", done))
            # a DONE read now (also one a fault wrapper made up for a silent host) settles
            # everything before it: those DONEs were sent before it
            drain(block=not isinstance(done, PendingDone))
            rig.complete(done)
            if on_quantum is not None:
                on_quantum(rig.now_us)
            wall = time.perf_counter() - wall0
            if speed is not None:
                ahead = rig.now_us / 1e6 / speed - wall
                if ahead > 0:
                    time.sleep(ahead)  # pacing policy of the tool, never of the simulation
            if progress is not None and wall >= next_progress:
                progress(res, wall)
                next_progress = wall + 0.5
    except BaseException as exc:
        res.reason = "crashed"
        res.error = f"{type(exc).__name__}: {exc}"
        raise
    finally:
        drain(block=res.reason != "crashed")
        res.end_us = rig.now_us
        res.state_durations_us[res.host_state] = (res.state_durations_us.get(res.host_state, 0)
                                                  + res.end_us - state_since)
        res.wall_s = time.perf_counter() - wall0
        if res.reason != "crashed":
            bye = host.finish(ls.End(at_us=rig.now_us, reason=res.reason))
            res.host_stats = bye.stats
            trace.write({"ev": "end", "t_us": rig.now_us, "reason": res.reason,
                         "host_state": res.host_state})
    return res


# How long the host process of a run at full speed polls for the next grant before it sleeps
# (docs/cosim.md, "Busy polling"): longer than the rig takes between two grants but for rare
# stalls (a plan among obstacles), so a host left alone still goes to sleep.
