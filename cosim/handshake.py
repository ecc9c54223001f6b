"""The quiet/elision/pipelining handshake between the rig, the session loop and a host end.

Spec: docs/cosim.md ("Pipelining", "Fewer messages", "Early grants"). One typed interface, no
attribute probing:

- the host's DONE carries ``quiet_until`` in its load: the simulated time up to which it promises
  to write nothing and change no state, task or camera wish;
- :func:`quiet_done` is the DONE such a promise fixes for a grant that brings the host nothing,
  so the grant need not be sent at all ("elided");
- a :class:`PendingDone` is the DONE of a grant sent ahead, resolved later through its
  :class:`Ticket`; every DONE answers :meth:`~mobigrasp.cosim.lockstep.Done.writes_nothing`,
  which :meth:`mobigrasp.cosim.rig.Rig.quiet_through` asks before it issues a grant early;
- :class:`HostEnd` is what the session loop calls on a host (a socket host, an in-process host
  or a fault wrapper around either).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Protocol

from mobigrasp.cosim import lockstep as ls


class HostEnd(Protocol):
    """The host as the session loop drives it (mobigrasp.cosim.hosts, .faulted_host)."""

    def submit(self, grant: ls.Grant) -> ls.Done:
        """Send a grant; its DONE, or a :class:`PendingDone` for one still to be read."""

    def exchange(self, grant: ls.Grant) -> ls.Done:
        """Send a grant and return the DONE the rig may complete its quantum with."""

    def early_wanted(self, start_us: int) -> bool:
        """Whether a grant starting at ``start_us`` is worth issuing early (Rig.grants_due)."""

    def finish(self, end: ls.End) -> ls.Bye:
        """End the run; the host's BYE with its final statistics."""

    def close(self) -> None:
        """Release the host (process, socket, shared memory)."""

    def traffic(self) -> HostTraffic:
        """What crossed the channel, for the summary (profiling only)."""


@dataclass(frozen=True)
class HostTraffic:
    """Lockstep traffic of a run: wall seconds in the host (or blocked on it), grants elided
    (their DONE known, :func:`quiet_done`), socket writes of grants (None in process)."""

    wall_host_s: float = 0.0
    elided: int = 0
    messages_sent: int | None = None


class TicketHost(Protocol):
    """The host end that reads a :class:`Ticket`'s DONE (mobigrasp.cosim.hosts.SocketHost)."""

    def read_through(self, ticket: Ticket) -> None:
        """Read DONEs in order until ``ticket``'s has arrived."""

    def promise(self, ticket: Ticket) -> bool:
        """Whether the last DONE read promises ``ticket``'s quantum quiet (recorded on it)."""


def quiet_done(grant: ls.Grant, last_load: dict) -> ls.Done | None:
    """The DONE the host gives for ``grant`` without being asked, or None if it cannot be told.

    A grant that brings no UART bytes and no frames, ends at or before the host's ``quiet_until``
    (from ``last_load``, the load of the host's last DONE, itself covering every quantum since)
    and finishes no load window gives the host nothing to do: it writes nothing, changes no
    state, task or camera wish (its quiet_until promise, docs/cosim.md), logs no event (events
    come from ticks, frames and received bytes) and reports no window (windows are reported at
    the quantum that ends them). Its DONE is therefore known: the rig need not send that grant
    at all ("elided" grants). The host's clock simply jumps over it to the next grant it gets.
    Checked against the real DONEs by the hosts' ``verify_elided``
    (tests/unit/cosim/test_runner_elision.py)."""
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



@dataclass(frozen=True)
class PendingDone(ls.Done):
    """The DONE of a grant sent ahead (pipelining, docs/cosim.md). With a promise (the grant
    ends at or before the host's ``quiet_until``): no bytes, and the state, finished and camera
    flags of the last DONE read; the rig may complete the quantum with it. Without one it is only
    a claim on the DONE: :func:`needed` reads it. Either way its events and load windows arrive
    later: :func:`resolved` (which applies ``fix``, a wrapper's change to the real DONE)."""

    ticket: Ticket | None = field(default=None, compare=False)
    fix: Callable[[ls.Done], ls.Done] | None = field(default=None, compare=False)

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
class Ticket:
    """One grant whose DONE is still to be read from the socket."""

    host: TicketHost
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


