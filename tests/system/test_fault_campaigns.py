"""Issue 9's targets at small N (slow): the same campaigns `mobigrasp campaign` runs at N = 100
(docs/faults.md has the N = 100 figures), here on 6 random 002 scenarios each.

- bit error rate 1e-4: success >= 95 % (here: every run), 1e-3: success >= 80 %, no unsafe
  actuation;
- a host crash at a random time: the wheels stopped within the watchdog + 50 ms in every run;
- an MCU reset at a random time: every run recovered (the task then succeeded) or failed
  cleanly, no unsafe actuation.
"""

import pytest

from mobigrasp.mcu_sim.faults.plan import parse_fault_overrides
from mobigrasp.services.campaign import CampaignConfig, run_campaign

pytestmark = pytest.mark.slow
RUNS = 6
SEED = 1005  # seeds of the issue-8 acceptance campaign that succeed without faults


def _run(tmp_path, *faults: str, random_times: bool = False) -> dict:
    cfg = CampaignConfig("002", RUNS, parse_fault_overrides(list(faults)), seed=SEED,
                         random_times=random_times, out=tmp_path)
    return run_campaign(cfg, progress=None)


def _campaign(tmp_path, *faults: str, random_times: bool = False) -> dict:
    return _run(tmp_path, *faults, random_times=random_times)["summary"]


def test_bit_error_rate_1e4(tmp_path):
    agg = _campaign(tmp_path, "uart_bit_error_rate=1e-4")
    assert agg["success_rate"] >= 0.95, agg["failed_seeds"]
    assert agg["unsafe_actuations"] == 0 and agg["crc_errors"] > 0


def test_bit_error_rate_1e3(tmp_path):
    agg = _campaign(tmp_path, "uart_bit_error_rate=1e-3")
    assert agg["success_rate"] >= 0.8, agg["failed_seeds"]
    assert agg["unsafe_actuations"] == 0
    assert agg["retransmits"] > 0  # the faults really hit reliable commands


def test_host_crash_at_any_time_stops_the_wheels_in_time(tmp_path):
    res = _run(tmp_path, "host_crash_at_s=30", random_times=True)
    agg = res["summary"]
    assert agg["late_stops"] == 0 and agg["unsafe_actuations"] == 0
    # one stop per crash that happened before the run ended, each within the limit
    crashed = sum(r["faults"]["host_crash_at_s"] < r["sim_time_s"] for r in res["rows"])
    assert crashed >= RUNS // 2 and agg["stop_latency_ms"]["n"] == crashed
    assert agg["stop_latency_ms"]["max"] <= 300.0


def test_mcu_reset_is_recovered_or_fails_cleanly(tmp_path):
    agg = _campaign(tmp_path, "mcu_reset_at_s=10", random_times=True)
    assert agg["unsafe_actuations"] == 0
    assert agg["fault_outcomes"]["stuck"] == 0, agg["failed_seeds"]
    assert agg["fault_outcomes"]["recovered"] + agg["fault_outcomes"]["failed_cleanly"] > 0
