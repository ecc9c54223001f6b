"""A grant issued one quantum early when it would be the same (cosim/rig.py grants_due).

With a lag, the grant for [T, T+Q) holds what the MCU and camera produced before T-Q. When the
quantum before that cannot produce anything (no frame slot, no host write, the MCU's TX line idle
through it), the rig issues the grant a quantum earlier: the host gets more time, and the grants
it gets must be exactly the same.
"""

import hashlib

import pytest

from mobigrasp.cosim.rig import Rig
from mobigrasp.mcu_sim.faults.injectors import RunFaults
from mobigrasp.mcu_sim.faults.plan import FaultPlan
from mobigrasp.mcu_sim.faults.safety import SafetyMonitor
from mobigrasp.mcu_sim.faults.wrappers import FaultedMcu
from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.services.run_job import RunOptions, execute

GRANT, QUIET = Rig.grant, Rig.quiet_through  # before any test patches them


def _record_grants(monkeypatch, tmp_path, early: bool) -> tuple[list, int, str, set]:
    grants, issued_early, depths = [], [0], set()
    grant, quiet = GRANT, QUIET

    def recording(self):
        g = grant(self)
        frames = tuple((f.seq, f.capture_us, f.arrival_us, hashlib.sha256(f.pixels).hexdigest())
                       for f in g.frames)
        grants.append((g.start_us, g.until_us, g.uart, frames))
        return g

    def counting(self, done, upto_us, issued=()):
        ok = quiet(self, done, upto_us, issued) if early else False
        issued_early[0] += ok
        if ok:  # quanta before the time it would have been issued at
            depths.add((upto_us - self.now_us) // self.config.quantum_us)
        return ok

    monkeypatch.setattr(Rig, "grant", recording)
    monkeypatch.setattr(Rig, "quiet_through", counting)
    s, _ = execute(RunOptions(scenario="paper000-exp1", transport="inproc",
                              out=tmp_path / str(early), progress=False, plots=False,
                              time_limit_s=4.0))
    assert s["status"] == "finished", s.get("error")
    assert s["lockstep"]["grants_early"] == issued_early[0]  # each quiet span: one early
    # the last one to three grants (lag 1, up to two early) are issued for quanta never run
    assert len(grants) - 1 - Rig.max_early_quanta <= s["lockstep"]["quanta"] <= len(grants) - 1
    return grants, issued_early[0], s["trace_sha256"], depths


def test_early_grants_are_the_grants_issued_later(monkeypatch, tmp_path):
    late, n_late, sha_late, _ = _record_grants(monkeypatch, tmp_path, early=False)
    early, n_early, sha_early, depths = _record_grants(monkeypatch, tmp_path, early=True)
    assert n_late == 0 and n_early > 300  # most quanta of 4 s: the MCU idle, no frame slot
    assert depths == {1, 2}  # one and two quanta early (Rig.max_early_quanta)
    assert early == late
    assert sum(bool(g[2]) for g in early) > 50 and sum(bool(g[3]) for g in early) > 40
    assert sha_early == sha_late


def test_mcu_tx_idle_through_follows_the_line_and_the_telemetry_time():
    mcu = Mcu()
    assert mcu.tx_idle_through_us() == 0  # telemetry is due at once after reset
    mcu.advance_to(1)  # the first telemetry frame is leaving now
    assert mcu.board.usart0.next_tx_cycle() is not None
    assert mcu.tx_idle_through_us() == 1
    mcu.advance_to(10_000)  # sent (about 4 ms at 115200 baud), the next one 20 ms after reset
    mcu.uart_tx_take()
    due = mcu.firmware.next_unprompted_send_us()
    assert mcu.board.usart0.next_tx_cycle() is None and due > 10_000
    assert mcu.tx_idle_through_us() == due
    # bytes on the RX line may be a frame to answer: nothing can be promised
    mcu.uart_rx(b"\x00\x01\x02", 10_000)
    assert mcu.tx_idle_through_us() == 10_000


def test_telemetry_off_means_idle_until_something_arrives():
    mcu = Mcu()
    mcu.advance_to(10_000)
    mcu.uart_tx_take()  # the rig takes what left at every coupling step
    mcu.firmware.params.values[:] = [0 if i == _telemetry_index() else v
                                     for i, v in enumerate(mcu.firmware.params.values)]
    assert mcu.firmware.next_unprompted_send_us() is None
    assert mcu.tx_idle_through_us() > 10**15


def _telemetry_index() -> int:
    from mobigrasp.mcu_sim.firmware import params as P
    return P.PARAM_INDEX[P.P_TELEMETRY_HZ]


@pytest.mark.parametrize("plan, idle", [(FaultPlan(), True),
                                        (FaultPlan(mcu_reset_at_s=1.0), False)])
def test_any_planned_fault_disables_early_grants(plan, idle):
    mcu = Mcu()
    mcu.advance_to(10_000)
    mcu.uart_tx_take()
    faulted = FaultedMcu(mcu, RunFaults(plan, seed=1), SafetyMonitor())
    assert (faulted.tx_idle_through_us() is not None) == idle
