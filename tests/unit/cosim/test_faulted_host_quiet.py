"""FaultedHost with a plan that never silences the host (no stall, no crash): its calls are the
inner host's own (bound once), and they answer what the general path (_serve) answers."""

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.faulted_host import FaultedHost
from mobigrasp.mcu_sim.faults.injectors import RunFaults
from mobigrasp.mcu_sim.faults.plan import FaultPlan


class _Host:
    def __init__(self) -> None:
        self.seen: list[int] = []

    def submit(self, grant: ls.Grant) -> ls.Done:
        self.seen.append(grant.start_us)
        return ls.Done(until_us=grant.until_us, writes=((grant.start_us + 7, 3),),
                       events=({"ev": "x", "t_us": grant.start_us},))

    exchange = submit

    def early_wanted(self, start_us: int) -> bool:
        return start_us % 10_000 == 0


def _grants(n: int) -> list[ls.Grant]:
    return [ls.Grant(start_us=k * 5_000, until_us=(k + 1) * 5_000, uart=(), frames=())
            for k in range(n)]


def test_quiet_plan_binds_the_inner_calls_with_the_same_answers():
    fast_inner, slow_inner = _Host(), _Host()
    fast = FaultedHost(fast_inner, RunFaults(FaultPlan(), 1))
    assert fast.submit == fast_inner.submit and fast.early_wanted == fast_inner.early_wanted
    slow = FaultedHost(slow_inner, RunFaults(FaultPlan(), 1))
    for g in _grants(12):
        assert fast.submit(g) == slow._serve(g, slow_inner.submit)
        assert fast.exchange(g) == slow._serve(g, slow_inner.exchange)
        assert fast.early_wanted(g.start_us) == FaultedHost.early_wanted(slow, g.start_us)
    assert fast_inner.seen == slow_inner.seen and fast.quanta_skipped == 0


def test_a_plan_that_silences_the_host_keeps_the_general_path():
    inner = _Host()
    host = FaultedHost(inner, RunFaults(FaultPlan(host_crash_at_s=0.01), 1))
    assert host.submit != inner.submit
    done = [host.submit(g) for g in _grants(4)]
    assert inner.seen == [0, 5_000] and host.quanta_skipped == 2
    assert done[2].events[0]["fault"] == "host_crash" and not done[3].events
