"""The host's silence from the fault plan: a host end frozen during a stall, gone after a crash.

During ``host_stall`` and after ``host_crash_at_s`` (docs/faults.md) the host program gets no
quantum: it reads and writes nothing, its frames are lost. The bytes the MCU sent meanwhile are
kept off the line by mobigrasp.mcu_sim.faults.wrappers.FaultedMcu, from the same
:class:`RunFaults`. :func:`wrap_for_faults` wraps the three things the rig talks to at once.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.handshake import HostEnd, HostTraffic, PendingDone
from mobigrasp.mcu_sim.faults.injectors import RunFaults
from mobigrasp.mcu_sim.faults.plan import FaultPlan
from mobigrasp.mcu_sim.faults.wrappers import FaultRig


class FaultedHost:
    """A host end frozen during a stall and silent for good after a crash."""

    def __init__(self, host: HostEnd, faults: RunFaults) -> None:
        self.inner = host
        self.faults = faults
        self._silent_reported: set[str] = set()
        self.quanta_skipped = 0
        self._resumed = False  # after a stall: writes dated inside it leave at resume time
        if faults.stall is None and faults.crash_us is None:
            # a host never silenced (the common case, an empty plan): every grant goes straight
            # to it, as _serve would pass it on (the runner binds these once per run)
            self.exchange = host.exchange
            self.submit = host.submit
            self.early_wanted = host.early_wanted

    def exchange(self, grant: ls.Grant) -> ls.Done:
        """Serve the grant, or answer for a host that is not running (no bytes, no events)."""
        return self._serve(grant, self.inner.exchange)

    def early_wanted(self, start_us: int) -> bool:
        """The inner host's wish for early grants."""
        return self.inner.early_wanted(start_us)

    def submit(self, grant: ls.Grant) -> ls.Done:
        """Like :meth:`exchange` without waiting (the runner's pipelined path)."""
        return self._serve(grant, self.inner.submit)

    def _serve(self, grant: ls.Grant, call: Callable[[ls.Grant], ls.Done]) -> ls.Done:
        f = self.faults
        if f.host_silent(grant.start_us):
            # FaultedMcu keeps the MCU's bytes off the line meanwhile; the frames are lost
            self.quanta_skipped += 1
            kind = "host_crash" if f.host_crashed(grant.start_us) else "host_stall"
            events: tuple[dict, ...] = ()
            if kind not in self._silent_reported:
                self._silent_reported.add(kind)
                events = ({"ev": "fault", "fault": kind, "t_us": grant.start_us},)
            return ls.Done(until_us=grant.until_us, events=events)
        if "host_stall" in self._silent_reported:
            self._resumed = True
        self._silent_reported.discard("host_stall")
        done = call(grant)
        if not self._resumed:
            return done
        start = grant.start_us

        def fix(real: ls.Done) -> ls.Done:
            # what the frozen program had queued (or computes for the missed ticks) leaves when
            # it runs again: no byte can go out while it was stalled
            if not any(t < start for t, _ in real.writes):
                return real
            return replace(real, writes=tuple((max(t, start), n) for t, n in real.writes))

        if isinstance(done, PendingDone) and done.ticket is not None:  # read later: fixed then
            return replace(done, fix=fix)
        return fix(done)

    def finish(self, end: ls.End) -> ls.Bye:
        """End of run: the host's statistics (a crashed host's as they were)."""
        return self.inner.finish(end)

    def close(self) -> None:
        """Release the host."""
        self.inner.close()

    def traffic(self) -> HostTraffic:
        """The inner host's traffic."""
        return self.inner.traffic()


def wrap_for_faults(plan: FaultPlan, seed: int, mcu: Any, plant: Any,
                    host: HostEnd | None = None) -> tuple[FaultRig, Any, Any, Any]:
    """(FaultRig, mcu, plant, host) wrapped by the plan: the one call the run code needs
    (docs/faults.md); ``host`` may be None (then None comes back)."""
    fr = FaultRig(plan, seed)
    m, p = fr.wrap(mcu, plant)
    if host is None:
        return fr, m, p, None
    h = FaultedHost(host, fr.faults)
    fr.host_quanta_skipped = lambda: h.quanta_skipped
    return fr, m, p, h
