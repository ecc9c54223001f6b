"""Campaigns on a Dask cluster, and incremental rows that survive an interruption."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from mobigrasp.mcu_sim.faults.plan import FaultPlan
from mobigrasp.services.campaign import ROWS_FILE, CampaignConfig, load_rows, run_campaign
from mobigrasp.services.campaign_engines import EngineError, check_scheduler, open_engine
from mobigrasp.tools.cli import main


def _fake(job: dict) -> dict:
    return {"status": "finished", "success": job["seed"] % 2 == 0, "task_state": "DONE",
            "sim_time_s": 1.0, "trace_sha256": f"sha-{job['seed']}",
            "protocol": {"retransmits": job["seed"]}}


class Interrupt:
    """A run function that is Ctrl-C'd at its ``at``-th call."""

    def __init__(self, at: int) -> None:
        self.at, self.calls = at, 0

    def __call__(self, job: dict) -> dict:
        self.calls += 1
        if self.calls == self.at:
            raise KeyboardInterrupt
        return _fake(job)


def _without_worker(rows: list[dict]) -> list[dict]:
    return [{k: v for k, v in r.items() if k != "worker"} for r in rows]


def test_rows_are_written_as_runs_finish_and_resume_runs_only_the_rest(tmp_path):
    cfg = CampaignConfig("000", 6, seed=10, jobs=1, out=tmp_path)
    with pytest.raises(KeyboardInterrupt):
        run_campaign(cfg, run_fn=Interrupt(at=4))
    kept, notes = load_rows(tmp_path / ROWS_FILE, [{"seed": s, "method": "000", "faults": {}}
                                                   for s in range(10, 16)])
    assert notes == []
    assert [r["seed"] for r in kept] == [10, 11, 12]  # the three finished before Ctrl-C
    counting = Interrupt(at=0)
    resumed = run_campaign(CampaignConfig("000", 6, seed=10, jobs=1, out=tmp_path,
                                          resume=True), run_fn=counting)
    assert counting.calls == 3  # only seeds 13, 14, 15 ran again
    whole = run_campaign(CampaignConfig("000", 6, seed=10, jobs=1, out=tmp_path / "whole"),
                         run_fn=_fake)
    assert _without_worker(resumed["rows"]) == _without_worker(whole["rows"])
    assert resumed["summary"] == whole["summary"]
    assert all(r["worker"] for r in resumed["rows"])


def test_a_torn_last_row_is_set_aside_and_a_foreign_row_refused(tmp_path):
    run_campaign(CampaignConfig("000", 3, seed=0, jobs=1, out=tmp_path), run_fn=_fake)
    path = tmp_path / ROWS_FILE
    path.write_text(path.read_text() + '{"seed": 2, "succ')
    jobs = [{"seed": s, "method": "000", "faults": {}} for s in range(3)]
    rows, notes = load_rows(path, jobs)
    assert [r["seed"] for r in rows] == [0, 1, 2]
    assert len(notes) == 1 and f"{path}: line 4: damaged row" in notes[0]
    other = CampaignConfig("000", 3, seed=0, jobs=1, out=tmp_path, resume=True,
                           faults=FaultPlan(uart_bit_error_rate=1e-3))
    with pytest.raises(ValueError, match="another campaign"):
        run_campaign(other, run_fn=_fake)


@pytest.mark.parametrize("address", ["localhost:8786", "tcp://host", "http://h:1",
                                     "tcp://h:99999", "tcp://h:1; rm -rf /"])
def test_bad_scheduler_addresses_are_refused_by_name(address):
    with pytest.raises(EngineError, match="--scheduler"):
        check_scheduler(address)


def test_cli_scheduler_errors_exit_2(tmp_path, capsys):
    assert main(["campaign", "--method", "000", "--runs", "1", "--scheduler", "nope",
                 "--out", str(tmp_path)]) == 2
    assert "--scheduler" in capsys.readouterr().err
    # nothing listens on this port: one line, exit 2
    assert main(["campaign", "--method", "000", "--runs", "1", "-q", "--scheduler",
                 "tcp://127.0.0.1:9", "--out", str(tmp_path)]) == 2
    assert "cannot reach the scheduler" in capsys.readouterr().err


def test_unknown_engine_is_refused_by_name():
    with pytest.raises(EngineError, match="unknown campaign engine 'mpi'"):
        open_engine("mpi")


@pytest.fixture
def dask_cluster(tmp_path):
    """A scheduler and two single-thread workers on localhost (the documented commands)."""
    pytest.importorskip("distributed")
    dask = Path(sys.executable).with_name("dask")
    env = {**os.environ, "DASK_DISTRIBUTED__WORKER__DAEMON": "False"}
    procs = []
    try:
        scheduler = subprocess.Popen(
            [str(dask), "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
             "--no-show"], stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path)
        procs.append(scheduler)
        address = None
        for line in scheduler.stderr:  # blocks until the scheduler says where it listens
            if "Scheduler at:" in line:
                address = line.split("Scheduler at:")[1].strip()
                break
        assert address and address.startswith("tcp://127.0.0.1:")
        for k in range(2):
            procs.append(subprocess.Popen(
                [str(dask), "worker", address, "--nthreads", "1", "--nworkers", "1",
                 "--no-dashboard", "--name", f"w{k}"], stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL, env=env, cwd=tmp_path))
        from distributed import Client

        with Client(address, timeout=60, set_as_default=False) as client:
            client.wait_for_workers(2, timeout=120)
            workers = set(client.scheduler_info()["workers"])
        yield address, workers
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


@pytest.mark.slow
def test_a_campaign_through_two_dask_workers_gives_the_local_rows(dask_cluster, tmp_path):
    address, workers = dask_cluster
    plan = FaultPlan(uart_bit_error_rate=1e-4)
    common = {"method": "000", "runs": 4, "faults": plan, "seed": 40, "time_limit_s": 3.0}
    on_dask = run_campaign(CampaignConfig(**common, out=tmp_path / "dask", scheduler=address))
    local = run_campaign(CampaignConfig(**common, out=tmp_path / "local", jobs=1))
    assert [r["seed"] for r in on_dask["rows"]] == [40, 41, 42, 43]
    assert all(r["trace_sha256"] for r in on_dask["rows"])
    assert _without_worker(on_dask["rows"]) == _without_worker(local["rows"])
    assert {r["worker"] for r in on_dask["rows"]} <= workers
    written = [json.loads(line) for line in (tmp_path / "dask" / ROWS_FILE).open()]
    assert sorted(r["seed"] for r in written) == [40, 41, 42, 43]
