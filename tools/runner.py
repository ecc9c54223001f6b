"""One closed-loop run: the rig's lockstep loop against a host over the pty or in process.

The SIM side (this process) owns simulated time: it grants quanta to the host, writes the trace,
samples ground truth, snapshots frames at state changes and paces to wall time when asked
(``speed``; pacing never changes what is simulated). The HOST side is either a subprocess
(``mobigrasp host --port /dev/pts/N --lockstep SOCK``) talking over a Unix socket and the real
pty, or the same objects called directly (``inproc``) with the lockstep messages still passed
through the codec, so both transports see byte-identical data.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import tempfile
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from mobigrasp.link import lockstep as ls
from mobigrasp.link.frame_ring import FrameRing

TERMINAL_STATES = ("DONE", "FAILED")


def quiet_done(grant: ls.Grant, last_load: dict) -> ls.Done | None:
    """The DONE the host gives for ``grant`` without being asked, or None if it cannot be told.

    A grant that brings no UART bytes and no frames, ends at or before the host's ``quiet_until``
    (from ``last_load``, the load of the host's last DONE, itself covering every quantum since)
    and finishes no load window gives the host nothing to do: it writes nothing, changes no
    state, task or camera wish (its quiet_until promise, docs/cosim.md), logs no event (events
    come from ticks, frames and received bytes) and reports no window (windows are reported at
    the quantum that ends them). Its DONE is therefore known: the rig need not send that grant
    at all ("elided" grants). The host's clock simply jumps over it to the next grant it gets.
    Checked against the real DONEs by ``verify_elided`` (tests/test_runner_elision.py)."""
    if grant.uart or grant.frames or not last_load:
        return None
    quiet = last_load.get("quiet_until", -1)
    window = last_load.get("window_us")
    if (type(quiet) is not int or grant.until_us > quiet or type(window) is not int
            or window <= 0 or grant.until_us // window != grant.start_us // window):
        return None
    return ls.Done(until_us=grant.until_us, writes=(), events=(),
                   load={"window_us": window, "windows": {}, "state": last_load.get("state"),
                         "finished": last_load.get("finished"),
                         "camera": last_load.get("camera"), "quiet_until": quiet})


def check_elided(predicted: ls.Done, real: ls.Done) -> None:
    """LockstepError unless the DONE predicted for an elided grant is the host's real one."""
    if predicted != real:
        raise ls.LockstepError(f"elided grant ending at {real.until_us} us: predicted DONE "
                               f"{predicted!r}, the host answered {real!r}")


class InprocHost:
    """The host program in this process, called directly."""

    verify_elided = False  # serve elided grants anyway and compare the DONEs (tests set it)

    def __init__(self, client: Any) -> None:
        self.client = client
        self.wall_host_s = 0.0  # wall seconds spent running the host program (profiling only)
        self.elided = 0
        self._last_load: dict = {}

    def submit(self, grant: ls.Grant) -> ls.Done:
        """Serve one grant now (in process nothing runs beside the rig)."""
        return self.exchange(grant)

    def exchange(self, grant: ls.Grant) -> ls.Done:
        """Serve one grant (a GRANT holds only ints and bytes: passed as is; the DONE goes
        through the codec so its events are exactly what the socket would deliver); a grant
        whose DONE is known (:func:`quiet_done`) is not served, as over the socket."""
        predicted = quiet_done(grant, self._last_load)
        if predicted is not None:
            self.elided += 1
            if not self.verify_elided:
                return predicted
        t0 = time.perf_counter()
        done = self.client.serve(grant)
        self.client.after_done()
        self.wall_host_s += time.perf_counter() - t0
        if done.events or done.load.get("windows"):
            done = ls.decode(ls.encode(done))
        # else the rest is ints, tuples of int pairs, a str and bools: the codec would give back
        # equal values (most quanta; checked in tests/test_runner_pipelining.py)
        if predicted is not None:
            check_elided(predicted, done)
        self._last_load = done.load
        return done

    def finish(self, end: ls.End) -> ls.Bye:
        """End the run; the host's final stats."""
        return ls.decode(ls.encode(self.client.bye()))

    def close(self) -> None:
        """Nothing to release."""


@dataclass(frozen=True)
class PendingDone(ls.Done):
    """The DONE of a grant sent ahead (pipelining, docs/cosim.md). With a promise (the grant
    ends at or before the host's ``quiet_until``): no bytes, and the state, finished and camera
    flags of the last DONE read; the rig may complete the quantum with it. Without one it is only
    a claim on the DONE: :func:`needed` reads it. Either way its events and load windows arrive
    later: :func:`resolved` (which applies ``fix``, a wrapper's change to the real DONE)."""

    ticket: Any = field(default=None, compare=False)
    fix: Any = field(default=None, compare=False)

    @property
    def promised(self) -> bool:
        """Whether the rig may complete the quantum before the real DONE is read."""
        return self.ticket is not None and self.ticket.promised is not None

    def writes_nothing(self) -> bool:
        """Whether the host certainly writes nothing in this quantum: its real DONE, read,
        has no writes, or the host promised so (also in a DONE read after the grant was sent).
        Rig.quiet_through asks, to issue a grant early."""
        t = self.ticket
        if t is None:
            return not self.writes
        if t.done is not None:
            return not t.done.writes
        return t.promised is not None or t.host.promise(t)


@dataclass
class _Ticket:
    """One grant whose DONE is still to be read from the socket."""

    host: Any
    start_us: int
    until_us: int
    promised: dict | None = None  # the provisional load of a PendingDone
    done: ls.Done | None = None
    predicted: ls.Done | None = None  # an elided grant's DONE, sent anyway to be checked


def resolved(done: ls.Done, block: bool = True) -> ls.Done | None:
    """The real DONE behind ``done`` (itself unless pending); None if not read yet and not
    ``block``."""
    if not isinstance(done, PendingDone):
        return done
    t = done.ticket
    if t.done is None and block:
        t.host.read_through(t)
    if t.done is None or done.fix is None:
        return t.done
    return done.fix(t.done)


def needed(done: ls.Done) -> ls.Done:
    """What the rig completes its quantum with: ``done`` itself, or a promised PendingDone (also
    one the host promised in a DONE read after the grant was sent), or else the real DONE, read
    now."""
    if not isinstance(done, PendingDone) or done.promised:
        return done
    t = done.ticket
    if t.done is None and t.host.promise(t):
        return replace(done, load=t.promised)
    real = resolved(done, block=True)
    assert real is not None
    return real


class SocketHost:
    """A host subprocess on the other end of a Unix socket (and of the pty).

    Pipelining: a grant that ends at or before the ``quiet_until`` of the last DONE read is
    answered at once with a :class:`PendingDone` (the host promised it writes nothing and
    changes no state there), so the rig simulates that quantum while the host serves it; the
    real DONE is read in order later and checked against the promise. At most ``max_ahead``
    grants are outstanding.

    Fewer messages: a promised grant whose DONE is known (:func:`quiet_done`) is not sent at all;
    other promised grants without frames wait in an outbox and leave together with the next
    grant the rig will need an answer to, one with frames (so vision starts early) or the last
    one before ``quiet_until`` (so the host parses their bytes before its tick), in one write;
    the host answers such a batch in one write too (host/lockstep_client.serve_stream).
    Messages and DONEs are the same as one by one."""

    max_ahead = 16
    verify_elided = False  # send elided grants anyway and check the host's DONEs (tests set it)

    def __init__(self, argv: list[str], accept_timeout_s: float = 60.0,
                 connect: bool = True, poll_ms: float = 0.0) -> None:
        """Start the host process; with ``connect`` (default) also wait for its HELLO, else
        call :meth:`connect` later (the caller builds its side while the host boots).
        ``poll_ms`` > 0: wait for the host's DONEs by polling the socket that long before
        sleeping (link.lockstep.SocketReader; docs/cosim.md, "Busy polling")."""
        if not poll_ms >= 0.0:
            raise ValueError(f"poll_ms must be >= 0, got {poll_ms!r}")
        self._poll_s = poll_ms / 1000.0
        self._accept_timeout_s = accept_timeout_s
        self.elided = 0
        self.messages_sent = 0  # socket writes of grants (profiling and tests)
        self._outbox = bytearray()  # encoded grants not written yet
        self._waiting: deque[_Ticket] = deque()
        self._quiet_until = -1
        self._last_load: dict = {}
        self._ring: FrameRing | None = None  # frames out of band (link/frame_ring.py)
        self.wall_host_s = 0.0  # wall seconds blocked on the host's DONEs (profiling only)
        self._encoding: _Ticket | None = None
        self._dir = tempfile.TemporaryDirectory(prefix="mobigrasp-ls-")
        self.path = os.path.join(self._dir.name, "lockstep.sock")
        self._server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self._server.bind(self.path)
        self._server.listen(1)
        self._server.settimeout(accept_timeout_s)
        env = dict(os.environ)
        # the host process imports this source tree whatever the caller's working directory
        root = str(Path(__file__).resolve().parents[1])
        env["PYTHONPATH"] = root + os.pathsep + env.get("PYTHONPATH", "")
        self.proc = subprocess.Popen([*argv, "--lockstep", self.path], env=env)
        if connect:
            self.connect()

    def connect(self) -> None:
        """Accept the host process's connection and read its HELLO."""
        timeout = self._accept_timeout_s
        try:
            self.conn, _ = self._server.accept()
        except TimeoutError as exc:
            self.proc.kill()
            raise ls.LockstepClosed(f"host process did not connect within {timeout} s"
                                    ) from exc
        self.conn.settimeout(timeout)  # safety limit only
        self.rfile = ls.SocketReader(self.conn, poll_s=self._poll_s)
        self.wfile = self.conn.makefile("wb")
        self._ring = FrameRing(slots=2 * self.max_ahead, directory=self._dir.name)
        hello = ls.read_message(self.rfile)
        if not isinstance(hello, ls.Hello) or hello.version != ls.LOCKSTEP_VERSION:
            raise ls.LockstepError(f"host said {hello!r}, expected HELLO v{ls.LOCKSTEP_VERSION}")

    def _send(self, msg: ls.Message) -> None:
        self._outbox += ls.encode(msg, frame_sink=self._share_frame)
        self._flush()

    def _flush(self) -> None:
        """Write the outbox (grants held back, then the message that needs them gone)."""
        if self._outbox:
            self.wfile.write(self._outbox)
            self.wfile.flush()
            self._outbox.clear()
            self.messages_sent += 1

    def _share_frame(self, pixels: bytes) -> dict | None:
        """Put a frame of the grant being sent into the ring (None: in the message after all).
        Its slot must not be in use: the grant that used it last has been decoded once its DONE
        was read (with 2 x max_ahead slots that is always so; read if not)."""
        ring = self._ring
        if ring is None:
            return None
        prior = ring.user[ring.next_slot()]
        if prior is not None and prior.done is None:
            self.read_through(prior)
        return ring.put(pixels, self._encoding)

    def _vanished(self, exc: Exception, t_us: int) -> ls.LockstepClosed:
        """A clear error for a host process that died or closed its end mid-run."""
        try:
            code = self.proc.wait(timeout=1.0)  # it is exiting: reap it to say how
        except subprocess.TimeoutExpired:
            code = None
        how = "is hung" if code is None else f"exited with code {code}"
        return ls.LockstepClosed(f"the host process vanished at t = {t_us / 1e6:.3f} s "
                                 f"simulated (it {how}; {type(exc).__name__}: {exc})")

    def submit(self, grant: ls.Grant) -> PendingDone:
        """Send a grant; never waits (but for the ``max_ahead``-th grant in flight): the DONE
        is a promise when the host's ``quiet_until`` covers the grant, else a claim."""
        ticket = _Ticket(self, grant.start_us, grant.until_us)
        # DONEs still on their way end before this grant, inside the same quiet_until promise:
        # the last one read speaks for them
        predicted = quiet_done(grant, self._last_load)
        if predicted is not None:
            self.elided += 1
            ticket.promised = dict(predicted.load)
            if not self.verify_elided:
                ticket.done = predicted
                return PendingDone(until_us=grant.until_us, load=ticket.promised, ticket=ticket)
            ticket.predicted = predicted
        self._encoding = ticket
        try:
            self._outbox += ls.encode(grant, frame_sink=self._share_frame)
            self._waiting.append(ticket)
            # held back while the rig will not need its DONE soon and it brings no frames; the
            # last one before a control tick's grant goes, with those held, ahead of that grant,
            # so the host parses their bytes before the tick instead of at it
            if (not self.promise(ticket) or grant.frames or len(self._waiting) > self.max_ahead
                    or 2 * grant.until_us - grant.start_us > self._quiet_until):
                self._flush()
        except OSError as exc:
            raise self._vanished(exc, grant.start_us) from exc
        if len(self._waiting) > self.max_ahead:
            self.read_through(self._waiting[0])
        if ticket.promised is not None:
            return PendingDone(until_us=grant.until_us, load=ticket.promised, ticket=ticket)
        return PendingDone(until_us=grant.until_us, ticket=ticket)

    def early_wanted(self, start_us: int) -> bool:
        """Whether a grant starting at ``start_us`` is worth issuing a quantum early
        (Rig.grants_due): the first one the host's last ``quiet_until`` does not cover (its
        control tick; the rig will wait for that DONE). Later ones would only go out as claims
        instead of being elided or batched once the tick's DONE is read."""
        return start_us <= self._quiet_until

    def promise(self, ticket: _Ticket) -> bool:
        """Whether the last DONE read promises ``ticket``'s quantum quiet (its ``quiet_until``
        covers it); if so the promise is recorded on the ticket, to be checked when the real
        DONE is read."""
        last = self._last_load
        if ticket.promised is None and last and ticket.until_us <= self._quiet_until:
            ticket.promised = {"window_us": last.get("window_us"), "windows": {},
                               "state": last.get("state"), "finished": last.get("finished"),
                               "camera": last.get("camera")}
        return ticket.promised is not None

    def exchange(self, grant: ls.Grant) -> ls.Done:
        """Send a grant; wait for its DONE, or answer a quiet one with a PendingDone."""
        done = self.submit(grant)
        return needed(done)

    def read_through(self, ticket: _Ticket) -> None:
        """Read DONEs in order until ``ticket``'s has arrived (sending what waits in the outbox
        first)."""
        if ticket.done is None and self._outbox:
            try:
                self._flush()
            except OSError as exc:
                raise self._vanished(exc, ticket.start_us) from exc
        while ticket.done is None:
            head = self._waiting[0]
            t0 = time.perf_counter()
            try:
                reply = ls.read_message(self.rfile)
            except (OSError, ls.LockstepClosed) as exc:
                raise self._vanished(exc, head.start_us) from exc
            self.wall_host_s += time.perf_counter() - t0
            if not isinstance(reply, ls.Done):
                raise ls.LockstepError(f"expected DONE, got {type(reply).__name__}")
            if reply.until_us != head.until_us:
                raise ls.LockstepError(f"DONE for until_us={reply.until_us}, expected "
                                       f"{head.until_us}")
            if head.promised is not None:
                broken = [k for k in ("state", "finished", "camera")
                          if reply.load.get(k) != head.promised[k]]
                if reply.writes or broken:
                    raise ls.LockstepError(
                        f"host broke its quiet_until promise in the quantum ending at "
                        f"{head.until_us} us (writes {list(reply.writes)}, changed {broken})")
            if head.predicted is not None:
                check_elided(head.predicted, reply)
            head.done = reply
            self._waiting.popleft()
            self._quiet_until = reply.load.get("quiet_until", -1)
            self._last_load = reply.load

    def finish(self, end: ls.End) -> ls.Bye:
        """Send END, wait for BYE (after the DONEs still on their way)."""
        if self._waiting:
            self.read_through(self._waiting[-1])
        self._send(end)
        reply = ls.read_message(self.rfile)
        if not isinstance(reply, ls.Bye):
            raise ls.LockstepError(f"expected BYE, got {type(reply).__name__}")
        return reply

    def close(self) -> None:
        """Close the socket and reap the host process."""
        for f in (getattr(self, "rfile", None), getattr(self, "wfile", None)):
            try:
                if f is not None:
                    f.close()
            except OSError:
                pass
        if hasattr(self, "conn"):
            self.conn.close()
        if self._ring is not None:
            self._ring.close()
        self._server.close()
        try:
            self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        self._dir.cleanup()


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


def run_session(rig: Any, host: Any, trace: Any, *, time_limit_us: int,
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
    submit = getattr(host, "submit", host.exchange)  # a host without it answers each at once
    early_wanted = getattr(host, "early_wanted", None)  # in process: every early grant

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
HOST_POLL_MS = 100.0


def host_argv(port_path: str, config_path: Path, poll_ms: float = 0.0) -> list[str]:
    """Command line of the host subprocess (without --lockstep, added by SocketHost).

    With ``MOBIGRASP_PROFILE_HOST=FILE`` in the environment the host runs under cProfile and
    writes its statistics to FILE (``python -m pstats FILE``): the pty run's other half."""
    prof = os.environ.get("MOBIGRASP_PROFILE_HOST")
    wrap = ["-m", "cProfile", "-o", prof] if prof else []
    poll = ["--poll-ms", f"{poll_ms:g}"] if poll_ms else []
    return [sys.executable, *wrap, "-m", "mobigrasp.tools.cli", "host", "--port", port_path,
            "--config", str(config_path), *poll]


def write_host_config(path: Path, config: dict) -> Path:
    """The host's configuration file (method, parameters, camera intrinsics: no ground truth)."""
    path.write_text(json.dumps(config, indent=2, sort_keys=True) + "\n")
    return path
