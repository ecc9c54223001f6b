"""Fault campaigns (docs/faults.md): scenario generation, aggregation, parallel runs, outputs, CLI.

The aggregation is tested with a stand-in run function (no closed loop); one tiny real run checks
the adapter to services.run_job."""

import json
import math

import pytest

from mobigrasp.mcu_sim.faults import FaultPlan, MotorFail, Window
from mobigrasp.services.campaign import (
    CampaignConfig,
    aggregate,
    format_table,
    jobs_of,
    make_scenario,
    randomize_times,
    row_of,
    run_campaign,
    run_one,
    scenario_toml,
    write_outputs,
)
from mobigrasp.tools.cli import main

PLAN = FaultPlan(uart_bit_error_rate=1e-3, uart_burst=Window(3.0, 0.5), host_crash_at_s=20.0)


@pytest.mark.parametrize("method", ["000", "001", "002"])
def test_generated_scenarios_follow_the_brief_and_carry_the_faults(method):
    bearings = []
    for seed in range(40):
        sc = make_scenario(method, seed, PLAN)
        assert sc.faults == PLAN and sc.meta.method == method and sc.meta.seed == seed
        dx, dy = sc.target.x_m - sc.robot.x_m, sc.target.y_m - sc.robot.y_m
        dist = math.hypot(dx, dy)
        assert 0.5 <= dist <= 3.0
        bearings.append(math.atan2(dy, dx))
        if method == "001" and dist > 1.4:
            assert 1 <= len(sc.obstacles) <= 3
        if method == "002":
            assert len(sc.target.path) >= 2  # the target moves
            first, last = sc.target.path[0], sc.target.path[-1]
            # during the approach only: over by the time a robot at 0.15 m/s, after a 1 s
            # search, has done 60 % of the way; at a hand's pace
            assert 0 < first.t_s < last.t_s <= 1.0 + 0.6 * dist / 0.15 + 0.01
            moved = math.hypot(last.x_m - first.x_m, last.y_m - first.y_m)
            assert 0 < moved / (last.t_s - first.t_s) <= 0.3
        else:
            assert not sc.target.path
    assert min(bearings) < -2 and max(bearings) > 2  # any bearing
    assert scenario_toml(method, 3, PLAN) == scenario_toml(method, 3, PLAN)
    assert scenario_toml(method, 3, PLAN) != scenario_toml(method, 4, PLAN)


def test_jobs_are_seeded_one_per_run():
    cfg = CampaignConfig("001", 5, PLAN, seed=100, out="/tmp/x")
    jobs = jobs_of(cfg)
    assert [j["seed"] for j in jobs] == [100, 101, 102, 103, 104]
    assert len({j["out"] for j in jobs}) == 5 and all(j["faults"] == PLAN.as_table()
                                                      for j in jobs)


@pytest.mark.parametrize("kw, fragment", [
    ({"method": "003"}, "--method"), ({"runs": 0}, "--runs"), ({"seed": -1}, "--seed"),
    ({"jobs": 0}, "--jobs"), ({"time_limit_s": 0.0}, "--time-limit-s"),
    ({"host": "fpga"}, "--host"),
])
def test_bad_config_is_named(kw, fragment):
    args = {"method": "000", "runs": 2} | kw
    with pytest.raises(ValueError, match=fragment):
        CampaignConfig(**args)


def fake_run(job):
    """Stand-in for the closed loop: outcome is a function of the seed."""
    seed = job["seed"]
    if seed % 7 == 6:
        raise RuntimeError(f"boom {seed}")
    return {
        "status": "finished", "success": seed % 3 != 0, "task_state": "DONE",
        "sim_time_s": 10.0 + seed, "contacts": 1 if seed == 4 else 0,
        "protocol": {"retransmits": seed, "crc_errors": 2 * seed, "watchdog_trips": 9},
        "safety": {"unsafe_actuations": 2 if seed == 5 else 0, "watchdog_trips": seed % 2,
                   "stop_latency_ms": [250.0 + seed], "recovery_ms": [100.0 * seed],
                   "unrecovered": 0},
        "faults": {"plan": job["faults"]},
    }


def test_aggregation_over_a_stand_in_run(tmp_path):
    cfg = CampaignConfig("000", 10, PLAN, seed=0, jobs=1, out=tmp_path)
    res = run_campaign(cfg, run_fn=fake_run, progress=None)
    agg, rows = res["summary"], res["rows"]
    assert [r["seed"] for r in rows] == list(range(10))
    crashed = [6]
    ok = [s for s in range(10) if s % 3 != 0 and s not in crashed]
    assert agg["runs"] == 10 and agg["successes"] == len(ok)
    assert agg["success_rate"] == pytest.approx(len(ok) / 10)
    assert agg["crashed_runs"] == 1 and rows[6]["error"] == "RuntimeError: boom 6"
    assert agg["unsafe_actuations"] == 1 + 2 and agg["runs_with_unsafe_actuation"] == 2
    assert agg["collisions"] == 1
    live = [s for s in range(10) if s not in crashed]
    assert agg["watchdog_trips"] == sum(s % 2 for s in live)  # the monitor's count wins
    assert agg["retransmits"] == sum(live) and agg["crc_errors"] == 2 * sum(live)
    assert agg["stop_latency_ms"] == {"n": 9, "median": 254.0, "max": 259.0}
    assert agg["stops_while_moving"] == 9
    assert agg["recovery_ms"]["max"] == 900.0 and agg["recovery_ms"]["n"] == 9
    assert agg["failed_seeds"] == sorted(set(range(10)) - set(ok))
    assert agg["runs_safety_monitored"] == 9 and agg["runs_faults_applied"] == 9
    # the link recovered in every live run; the task then succeeded in the ok ones, and the
    # others ended DONE without success: stuck, not recovered
    assert agg["fault_outcomes"] == {"recovered": len(ok), "failed_cleanly": 0,
                                     "stuck": len(live) - len(ok)}
    assert agg["late_stops"] == 0
    text = format_table(agg)
    assert "success rate" in text and f"{len(ok) / 10 * 100:.1f} %" in text
    assert "unsafe actuations" in text and "retransmits" in text


def test_parallel_runs_give_the_same_rows(tmp_path):
    serial = run_campaign(CampaignConfig("002", 8, PLAN, seed=3, jobs=1, out=tmp_path),
                          run_fn=fake_run, progress=None)
    parallel = run_campaign(CampaignConfig("002", 8, PLAN, seed=3, jobs=2, out=tmp_path),
                            run_fn=fake_run, progress=None)
    assert [r.pop("worker") for r in parallel["rows"]] != []  # where it ran: not a result
    for r in serial["rows"]:
        r.pop("worker")
    assert parallel == serial


def test_progress_bar_goes_to_the_stream(tmp_path, capsys):
    import io

    from mobigrasp.tools.progress import Progress

    buf = io.StringIO()
    run_campaign(CampaignConfig("000", 3, seed=0, jobs=1, out=tmp_path), run_fn=fake_run,
                 progress=Progress(total=3, desc="campaign", unit="runs", stream=buf))
    assert "3/3 runs" in buf.getvalue() and capsys.readouterr().out == ""
    assert "\r" not in buf.getvalue()  # not a terminal: whole lines


def test_rows_without_a_safety_block_are_marked():
    row = row_of({"seed": 1}, {"status": "finished", "success": True, "contacts": 2,
                              "protocol": {"watchdog_trips": 3, "retransmits": 4}})
    assert row["safety_monitored"] is False and row["unsafe_actuations"] == 2
    assert row["watchdog_trips"] == 3 and row["retransmits"] == 4 and not row["faults_applied"]
    agg = aggregate([row], CampaignConfig("000", 1, PLAN))
    assert "only 0/1 runs carried a safety monitor" in format_table(agg)
    assert "applied the faults in only 0/1" in format_table(agg)


def test_outputs_json_and_plot(tmp_path):
    res = run_campaign(CampaignConfig("001", 6, PLAN, jobs=1, out=tmp_path), run_fn=fake_run,
                       progress=None)
    js, png = write_outputs(res, tmp_path / "out")
    assert json.loads(js.read_text()) == res
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 5000


@pytest.mark.parametrize("argv, fragment", [
    (["--method", "000", "--fault", "uart_bit_error_rate=2"], "faults.uart_bit_error_rate"),
    (["--method", "000", "--fault", "nope=1"], "faults.nope: unknown key"),
    (["--method", "000", "--runs", "0"], "--runs"),
])
def test_cli_bad_input_exits_2(argv, fragment, capsys):
    try:
        code = main(["campaign", *argv])
    except SystemExit as exc:  # refused by argparse (--runs)
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err
    assert fragment in err and len(err.strip().splitlines()) == 1


def test_cli_method_not_in_the_c_host_is_one_line(capsys, tmp_path):
    from mobigrasp import hostc
    from mobigrasp.host.task import METHODS

    have = hostc.program_methods([str(hostc.executable())])
    missing = [m for m in METHODS if m not in have]
    if not missing:
        pytest.skip("every method is in the C host")
    assert main(["campaign", "--method", missing[0], "--host", "c", "--runs", "1",
                 "--out", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"method {missing[0]} is not in the C host yet" in err[0]
    assert not (tmp_path / "c").exists()


def test_cli_unknown_method_is_refused_by_argparse(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["campaign", "--method", "009"])
    assert exit_.value.code == 2 and "--method" in capsys.readouterr().err


def test_one_tiny_real_run_through_the_adapter(tmp_path):
    job = jobs_of(CampaignConfig("000", 1, FaultPlan(uart_bit_error_rate=1e-3), seed=11,
                                 out=tmp_path, time_limit_s=2.0))[0]
    summary = run_one(job)
    assert summary["status"] == "finished" and summary["seed"] == 11
    assert summary["sim_time_s"] == pytest.approx(2.0)
    row = row_of(job, summary)
    assert row["status"] == "finished" and row["seed"] == 11
    assert (tmp_path / "runs" / "000-11" / "summary.json").exists()


def test_random_fault_times_are_seeded_and_in_range():
    plan = FaultPlan(host_crash_at_s=60.0, uart_burst=Window(10.0, 0.5),
                     motor_fail=MotorFail("left", 30.0), uart_bit_error_rate=1e-3)
    draws = [randomize_times(plan, s) for s in range(50)]
    assert randomize_times(plan, 7) == draws[7]
    crash = [p.host_crash_at_s for p in draws]
    assert all(0 <= c <= 60 for c in crash) and len(set(crash)) > 40 and max(crash) > 45
    assert all(p.uart_burst.duration_s == 0.5 and 0 <= p.uart_burst.start_s <= 10 for p in draws)
    assert all(p.motor_fail.wheel == "left" and p.uart_bit_error_rate == 1e-3 for p in draws)
    assert randomize_times(FaultPlan(), 3) == FaultPlan()
    cfg = CampaignConfig("000", 3, plan, seed=5, random_times=True)
    assert [j["faults"]["host_crash_at_s"] for j in jobs_of(cfg)] == crash[5:8]


@pytest.mark.parametrize("state, success, unsafe, unrecovered, recov, outcome", [
    ("DONE", True, 0, 0, [], None), ("DONE", True, 0, 0, [30.0], "recovered"),
    ("DONE", False, 0, 0, [30.0], "stuck"),  # DONE without the object
    ("APPROACH", False, 0, 0, [30.0], "stuck"),  # link back, task never finished
    ("FAILED", False, 0, 0, [30.0], "failed_cleanly"),
    ("FAILED", False, 0, 1, [], "failed_cleanly"), ("FAILED", False, 1, 1, [], "stuck"),
    ("SEARCH", False, 0, 1, [12.0], "stuck"),
])
def test_fault_outcome_of_a_run(state, success, unsafe, unrecovered, recov, outcome):
    row = row_of({"seed": 0}, {"status": "finished", "task_state": state, "success": success,
                               "safety": {
        "unsafe_actuations": unsafe, "unrecovered": unrecovered, "recovery_ms": recov,
        "late_stops": 0}})
    assert row["fault_outcome"] == outcome


def test_a_campaign_stopped_early_does_not_run_the_rest():
    """Ctrl-C or a kill while runs are queued: the runs not started are dropped, not run by a
    pool left to finish them (threads stand in for the processes, so the runs can be held)."""
    import threading
    from concurrent.futures import ThreadPoolExecutor

    from mobigrasp.services.campaign_engines import processes

    release, started, pools = threading.Event(), [], []

    def run_fn(job):
        started.append(job["seed"])
        if job["seed"]:
            release.wait()  # held until the campaign has been stopped
        return {"seed": job["seed"]}

    def pool(max_workers):
        pools.append(ThreadPoolExecutor(max_workers=max_workers))
        return pools[0]

    results = processes(run_fn, [{"seed": k} for k in range(20)], workers=2, pool_factory=pool)
    first = next(results)
    assert first[1] == {"seed": 0}
    results.close()  # the consumer stops: KeyboardInterrupt, a kill of the campaign
    release.set()
    pools[0].shutdown(wait=True)
    assert len(started) <= 3  # seed 0 and the two that were running; 17 never started
