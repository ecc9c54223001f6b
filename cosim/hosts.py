"""The host ends of a run: the host program in this process, or a subprocess over a socket.

Both implement :class:`mobigrasp.cosim.handshake.HostEnd`. The HOST side is either a subprocess
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
import time
from collections import deque
from pathlib import Path
from typing import Any

from mobigrasp.cosim import leftovers
from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.frame_ring import FrameRing
from mobigrasp.cosim.handshake import (
    HostTraffic,
    PendingDone,
    Ticket,
    check_elided,
    needed,
    quiet_done,
)


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

    def early_wanted(self, start_us: int) -> bool:
        """Every early grant helps: in process the host answers at once."""
        return True

    def traffic(self) -> HostTraffic:
        """Wall seconds in the host program and grants elided (no socket writes)."""
        return HostTraffic(wall_host_s=self.wall_host_s, elided=self.elided)

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
        # equal values (most quanta; checked in tests/unit/cosim/test_runner_pipelining.py)
        if predicted is not None:
            check_elided(predicted, done)
        self._last_load = done.load
        return done

    def finish(self, end: ls.End) -> ls.Bye:
        """End the run; the host's final stats."""
        return ls.decode(ls.encode(self.client.bye()))

    def close(self) -> None:
        """Nothing to release."""



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
    the host answers such a batch in one write too (drivers/lockstep.serve_stream).
    Messages and DONEs are the same as one by one."""

    max_ahead = 16
    verify_elided = False  # send elided grants anyway and check the host's DONEs (tests set it)

    def __init__(self, argv: list[str], accept_timeout_s: float = 60.0,
                 connect: bool = True, poll_ms: float = 0.0) -> None:
        """Start the host process; with ``connect`` (default) also wait for its HELLO, else
        call :meth:`connect` later (the caller builds its side while the host boots).
        ``poll_ms`` > 0: wait for the host's DONEs by polling the socket that long before
        sleeping (cosim.lockstep.SocketReader; docs/cosim.md, "Busy polling")."""
        if not poll_ms >= 0.0:
            raise ValueError(f"poll_ms must be >= 0, got {poll_ms!r}")
        self._poll_s = poll_ms / 1000.0
        self._accept_timeout_s = accept_timeout_s
        self.elided = 0
        self.messages_sent = 0  # socket writes of grants (profiling and tests)
        self._outbox = bytearray()  # encoded grants not written yet
        self._waiting: deque[Ticket] = deque()
        self._quiet_until = -1
        self._last_load: dict = {}
        self._ring: FrameRing | None = None  # frames out of band (cosim/frame_ring.py)
        # the first grant that named the ring: once its DONE is read the host has mapped it
        self._ring_first: Ticket | None = None
        self.wall_host_s = 0.0  # wall seconds blocked on the host's DONEs (profiling only)
        self._encoding: Ticket | None = None
        self.conn: socket.socket | None = None  # set by connect()
        self.rfile: ls.SocketReader | None = None
        self.wfile: Any = None
        self._dir = leftovers.temp_dir("ls")
        self.path = os.path.join(self._dir.name, "lockstep.sock")
        self._server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self._server.bind(self.path)
        self._server.listen(1)
        self._server.settimeout(accept_timeout_s)
        self.proc = subprocess.Popen([*argv, "--lockstep", self.path])
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
        os.unlink(self.path)  # both ends have the connection: the name is not needed again
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
        if self._ring_first is None:
            self._ring_first = self._encoding
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
        ticket = Ticket(self, grant.start_us, grant.until_us)
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

    def promise(self, ticket: Ticket) -> bool:
        """Whether the last DONE read promises ``ticket``'s quantum quiet (its ``quiet_until``
        covers it); if so the promise is recorded on the ticket, to be checked when the real
        DONE is read."""
        last = self._last_load
        if ticket.promised is None and last and ticket.until_us <= self._quiet_until:
            ticket.promised = {"window_us": last.get("window_us"), "windows": {},
                               "state": last.get("state"), "finished": last.get("finished"),
                               "camera": last.get("camera")}
        return ticket.promised is not None

    def traffic(self) -> HostTraffic:
        """Wall seconds blocked on the host's DONEs, grants elided, socket writes of grants."""
        return HostTraffic(wall_host_s=self.wall_host_s, elided=self.elided,
                           messages_sent=self.messages_sent)

    def exchange(self, grant: ls.Grant) -> ls.Done:
        """Send a grant; wait for its DONE, or answer a quiet one with a PendingDone."""
        done = self.submit(grant)
        return needed(done)

    def read_through(self, ticket: Ticket) -> None:
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
            if head is self._ring_first:  # the host decoded it, so it has mapped the ring
                self._ring.unlink()
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
        for f in (self.rfile, self.wfile):
            try:
                if f is not None:
                    f.close()
            except OSError:
                pass
        if self.conn is not None:
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
