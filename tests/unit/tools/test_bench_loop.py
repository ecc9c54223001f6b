"""``mobigrasp bench loop --runs 0``: real-time factors over both transports at both lags."""

import json

import pytest

from mobigrasp.tools.cli import main


def test_bench_loop_reports_rtf_against_the_strict_alternation_baseline(tmp_path):
    out = tmp_path / "loop.json"
    assert main(["bench", "loop", "--runs", "0", "--rtf-limit-s", "0.4", "--rtf-repeats", "2",
                 "--json", str(out)]) == 0
    fig = json.loads(out.read_text())
    for tag in ("pty", "inproc", "pty_lag0", "inproc_lag0", "pty_simavr", "host_python",
                "host_python_inproc", "host_c", "host_c_inproc", "host_arm"):
        runs = fig[f"realtime_factor_{tag}_runs"]
        assert len(runs) == 2 and all(r > 0 for r in runs)
        assert min(runs) <= fig[f"realtime_factor_{tag}"] <= max(runs)  # the median of them
        assert fig[f"sim_s_{tag}"] >= 0.4
        assert 0.0 < fig[f"wall_host_s_{tag}"] < fig[f"wall_s_{tag}"]
    assert fig["speedup_pty_vs_lag0"] == round(
        fig["realtime_factor_pty"] / fig["realtime_factor_pty_lag0"], 3)
    assert fig["simavr_vs_python_pty"] == round(
        fig["realtime_factor_pty_simavr"] / fig["realtime_factor_pty"], 3)
    assert fig["trace_equal_pty_inproc"] is True
    for host in ("c", "arm"):
        assert fig[f"host_{host}_vs_python"] == round(
            fig[f"realtime_factor_host_{host}"] / fig["realtime_factor_host_python"], 3)
    assert fig["host_c_inproc_vs_python_inproc"] == round(
        fig["realtime_factor_host_c_inproc"] / fig["realtime_factor_host_python_inproc"], 3)
    # the first paper scene whose method the C program has (002 at least), the others named
    assert (fig["host_scenario"], fig["host_method"]) in (
        ("paper000-exp1", "000"), ("paper001-sim1", "001"), ("paper002-marker", "002"))
    passed = {"paper000-exp1": [], "paper001-sim1": ["000"], "paper002-marker": ["000", "001"]}
    for method in passed[fig["host_scenario"]]:
        assert f"method {method} is not in the" in fig["host_method_reason"]
    assert fig["trace_equal_hosts"] is True
    assert "campaign" not in fig


def test_bench_loop_takes_the_five_configurations_in_turn(monkeypatch, tmp_path):
    """Run by run, not in blocks: the machine's speed drifts over minutes (tools/benches/loop)."""
    import mobigrasp.tools.benches.loop as loop
    order = []

    def fake_one(opts):
        order.append((opts.host_lag_quanta, opts.transport, opts.mcu))
        wall = 1.0 + 0.1 * len(order)  # drifting: each run slower than the last
        return {"wall_time_s": wall, "sim_time_s": 17.0, "realtime_factor": 17.0 / wall,
                "wall_host_s": 0.5, "trace_sha256": f"sha{opts.host_lag_quanta}"}

    monkeypatch.setattr(loop, "_one", fake_one)
    out = tmp_path / "loop.json"
    assert main(["bench", "loop", "--runs", "0", "--rtf-repeats", "3", "--rtf-hosts", "",
                 "--json", str(out)]) == 0
    configs = [(1, "pty", "python"), (1, "inproc", "python"), (0, "pty", "python"),
               (0, "inproc", "python"), (1, "pty", "simavr")]
    assert order == configs * 3
    fig = json.loads(out.read_text())
    # the medians of interleaved runs: the 2nd of each configuration's three
    assert fig["wall_s_pty"] == round(1.0 + 0.1 * 6, 3)
    assert fig["wall_s_inproc_lag0"] == round(1.0 + 0.1 * 9, 3)
    assert fig["wall_s_pty_simavr"] == round(1.0 + 0.1 * 10, 3)


def test_random_scenes_give_the_same_trace_over_the_pty_and_in_process(tmp_path):
    """Two short random scenes with light faults (001 with obstacles, 002), run by the campaign
    over each transport; the re-run command of a row repeats its trace."""
    import shlex

    from mobigrasp.services.loop_campaign import LoopCampaign, rerun_command, run_campaign

    sha = {}
    for transport in ("pty", "inproc"):
        cfg = LoopCampaign(methods=("001", "002"), runs=1, seed_base=1004, jobs=1,
                           out=tmp_path / transport, transport=transport, time_limit_s=3.0)
        result = run_campaign(cfg)
        for row in result["rows"]:
            assert row["transport"] == transport and row["sim_time_s"] >= 3.0
            assert "[faults]" in open(row["scene"]).read()
            sha[transport, row["method"]] = row["trace_sha256"]
    assert sha["pty", "001"] == sha["inproc", "001"] and sha["pty", "002"] == sha["inproc", "002"]
    assert sha["pty", "001"] != sha["pty", "002"]
    row = result["rows"][0]  # in process, 001
    argv = shlex.split(rerun_command(row))
    assert argv[0] == "mobigrasp" and main([*argv[1:], "--no-plots", "-q"]) == 1  # 3 s: no grasp
    again = json.loads((tmp_path / "inproc" / "runs" / "001-1004" / "summary.json").read_text())
    assert again["trace_sha256"] == sha["inproc", "001"]


def test_the_random_runs_host_is_in_their_rows_and_rerun_commands(tmp_path):
    from mobigrasp.services.loop_campaign import (
        CampaignInputError,
        LoopCampaign,
        jobs_of,
        rerun_command,
    )

    cfg = LoopCampaign(methods=("000",), runs=1, out=tmp_path, host="c", transport="inproc")
    job = jobs_of(cfg)[0]
    assert job["host"] == "c" and cfg.key("000")["host"] == "c"
    assert rerun_command({**job, "folder": "f"}).endswith("--host c")
    with pytest.raises(CampaignInputError, match="--host arm runs over the pty only"):
        LoopCampaign(methods=("000",), runs=1, out=tmp_path, host="arm", transport="inproc")


# a stand-in for the closed loop: the end of run (method, seed), as a summary would give it
FAKE_ENDS = {
    ("000", 1000): ("DONE", True, 4.0, 0), ("000", 1001): ("FAILED", False, None, 0),
    ("000", 1002): ("DONE", False, None, 0),  # a false claim
    ("002", 1000): ("DONE", True, 6.0, 0), ("002", 1001): ("SEARCH", False, None, 0),
    ("002", 1002): ("DONE", True, 2.0, 3),  # held, but touched an obstacle on the way
}
CALLS: list = []


def fake_run(job):
    """What run_job returns, and the trace line the failure reason is read from."""
    from pathlib import Path

    CALLS.append((job["method"], job["seed"]))
    state, held, err, contacts = FAKE_ENDS[job["method"], job["seed"]]
    folder = Path(job["folder"])
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "trace.jsonl").write_text(json.dumps(
        {"ev": "state", "from": "ADJUST", "to": state, "why": f"why {job['seed']}"},
        separators=(",", ":")) + "\n")
    claimed = state == "DONE"
    return {"status": "finished", "task_state": state, "claimed_success": claimed,
            "grasped": held, "success": claimed and held, "false_claim": claimed and not held,
            "end_reason": "time_limit" if state == "SEARCH" else f"task_{state.lower()}",
            "contacts": contacts, "final_error_mm": err, "sim_time_s": 30.0,
            "wall_time_s": 3.0, "trace_sha256": f"sha-{job['method']}-{job['seed']}"}


@pytest.fixture
def fake_loop(monkeypatch):
    import mobigrasp.services.loop_campaign as lc

    CALLS.clear()
    monkeypatch.setattr(lc, "run_job", fake_run)
    # seed 1001 of 002 is a board alone in the fake; a real v3 002 scene of a seed is whatever
    # the generator made it
    monkeypatch.setattr(lc, "graspable", lambda job: (job["method"], job["seed"]) != ("002", 1001))
    return lc


CAMPAIGN = ["bench", "loop", "--runs", "3", "--methods", "000,002", "--rtf-repeats", "0",
            "--jobs", "1"]


def test_campaign_table_failures_and_figure(fake_loop, tmp_path, capsys):
    out = tmp_path / "res" / "loop.json"
    assert main([*CAMPAIGN, "--json", str(out)]) == 0
    fig = json.loads(out.read_text())
    f000, f002 = fig["campaign"]["000"], fig["campaign"]["002"]
    assert (f000["graspable_runs"], f000["graspable_successes"], f000["false_claims"]) == (3, 1, 1)
    assert f000["final_error_mm_median"] == 4.0 and f000["failed_seeds"] == [1001, 1002]
    assert (f002["graspable_runs"], f002["board_alone_runs"], f002["board_alone_failed"]) \
        == (2, 1, 0)
    assert f002["contacts"] == 3 and f002["failed_seeds"] == [1001, 1002]
    assert fig["missed_runs"] == 4 and fig["transport"] == "pty" and fig["commit"]
    md = (tmp_path / "res" / "loop.md").read_text()
    assert md in capsys.readouterr().out  # printed as written
    assert "| method | commit | graspable scenes | success | false claims | contacts | board " \
           "alone FAILED | median final error |" in md
    assert f"| 000 | {fig['commit']} | 3 | 1/3 (33.3 %) | 1 | 0 | - | 4.0 mm |" in md
    assert f"| 002 | {fig['commit']} | 2 | 2/2 (100.0 %) | 0 | 3 | 0/1 | 4.0 mm |" in md
    runs = tmp_path / "res" / "loop-runs"
    for method, seed, cause in (("000", 1001, "ended FAILED (task_failed), contacts 0: why 1001"),
                                ("000", 1002, "false claim"),
                                ("002", 1001, "time limit in SEARCH"),
                                ("002", 1002, "success with contact")):
        item = next(block for block in md.split("\n- ")
                    if block.startswith(f"{method} seed {seed} "))
        assert cause in item and str(runs / "runs" / f"{method}-{seed}") in item
        assert (f"re-run: `mobigrasp run {runs / 'scenes'}/random-v3-{method}-{seed}.toml "
                f"--transport pty --out {runs / 'runs'}/{method}-{seed}`") in item
        assert (runs / "runs" / f"{method}-{seed}").is_dir()
    assert "000 seed 1000 " not in md and "002 seed 1000 " not in md  # met their bars
    from mobigrasp.services.random_scenarios import random_scenario_toml

    assert (runs / "scenes" / "random-v3-002-1001.toml").read_text() \
        == random_scenario_toml("002", 1001, "v3")
    png = (tmp_path / "res" / "loop.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_campaign_progress_lines(fake_loop, tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("MOBIGRASP_PROGRESS_INTERVAL_S", "0")  # a line at every run
    assert main([*CAMPAIGN, "--json", str(tmp_path / "loop.json")]) == 0
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("bench loop:")]
    assert len(lines) >= 5 and lines[-1].startswith("bench loop: 6/6 runs")
    # seed by seed with the methods side by side: 000 and 002 of seed 1000 first
    assert lines[0].startswith("bench loop: 2/6 runs  2 met the bar, 0 missed, elapsed ")
    assert all("elapsed" in ln for ln in lines)
    assert all(("left" in ln) is (" 6/6 " not in ln) for ln in lines)  # until the last run
    assert "(1 FALSE CLAIMS)" in lines[-1]


def test_progress_text_estimates_the_time_left():
    from mobigrasp.services.loop_campaign import progress_text

    rows = [{"met_bar": True, "false_claim": False}] * 3 + [{"met_bar": False,
                                                             "false_claim": True}]
    # 4 of 10 done, 2 of them in this session in 60 s: 6 more at 30 s each
    assert progress_text(4, 10, rows, 60.0, 2) == (
        "3 met the bar, 1 missed (1 FALSE CLAIMS), elapsed 1m00s, ~3m00s left")
    assert progress_text(10, 10, rows, 4000.0, 10).endswith("elapsed 1h06m")


class Killed(BaseException):
    """The campaign's process killed midway (not an error of one run)."""


def test_a_killed_campaign_resumes_without_losing_rows(fake_loop, tmp_path, capsys,
                                                       monkeypatch):
    out = tmp_path / "loop.json"

    def dies_at_the_fourth(job):
        if len(CALLS) == 3:
            raise Killed
        return fake_run(job)

    monkeypatch.setattr(fake_loop, "run_job", dies_at_the_fourth)
    with pytest.raises(Killed):
        main([*CAMPAIGN, "--json", str(out)])
    rows_file = tmp_path / "loop-runs" / "loop.rows.jsonl"
    first = rows_file.read_text().splitlines()
    assert len(first) == 3
    with rows_file.open("a") as fh:  # the line being written when it died
        fh.write('{"method": "000", "se')
    capsys.readouterr()
    monkeypatch.setattr(fake_loop, "run_job", fake_run)
    # without --resume the rows recorded are not thrown away
    assert main([*CAMPAIGN, "--json", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--resume" in err[0] and str(rows_file) in err[0]
    assert main([*CAMPAIGN, "--json", str(out), "--resume"]) == 0
    done_first = [(json.loads(x)["method"], json.loads(x)["seed"]) for x in first]
    assert sorted(CALLS[3:] + done_first) == sorted(FAKE_ENDS)  # only the rest ran
    fig = json.loads(out.read_text())
    assert fig["campaign"]["000"]["runs"] == 3 and fig["campaign"]["002"]["runs"] == 3
    # a resume with other options is refused: the rows are of another campaign
    assert main([*CAMPAIGN, "--json", str(out), "--resume", "--transport", "inproc"]) == 2
    assert "another campaign" in capsys.readouterr().err


@pytest.mark.parametrize(("extra", "fragment"), [
    (["--runs", "-1"], "--runs"),
    (["--methods", "000,003"], "unknown method '003'"),
    (["--methods", ","], "--methods"),
    (["--jobs", "0"], "--jobs"),
    (["--time-limit-s", "nan"], "--time-limit-s"),
    (["--rtf-repeats", "-1"], "--rtf-repeats"),
    (["--seed-base", "-5"], "--seed-base"),
])
def test_bad_campaign_options_exit_2_with_one_line(fake_loop, tmp_path, capsys, extra,
                                                   fragment):
    out = tmp_path / "loop.json"
    assert main(["bench", "loop", "--runs", "2", "--rtf-repeats", "0", *extra,
                 "--json", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and fragment in err[0] and "Traceback" not in err[0]
    assert not CALLS and not any(tmp_path.iterdir())  # nothing ran, nothing written


def test_a_json_path_that_is_a_folder_exits_2(fake_loop, tmp_path, capsys):
    (tmp_path / "here").mkdir()
    (tmp_path / "afile").write_text("x")
    for path in (tmp_path / "here", tmp_path / "afile" / "loop.json"):
        assert main([*CAMPAIGN, "--json", str(path)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and str(path) in err[0]
    assert not CALLS and sorted(p.name for p in tmp_path.iterdir()) == ["afile", "here"]


def test_a_resume_with_a_damaged_first_row_reruns_only_that_run(fake_loop, tmp_path, capsys):
    out = tmp_path / "loop.json"
    assert main([*CAMPAIGN, "--json", str(out)]) == 0
    rows_file = tmp_path / "loop-runs" / "loop.rows.jsonl"
    lines = rows_file.read_text().splitlines()
    first = json.loads(lines[0])
    rows_file.write_text("\n".join(["\x00garbled" + lines[0][9:]] + lines[1:]) + "\n")
    CALLS.clear()
    assert main([*CAMPAIGN, "--json", str(out), "--resume"]) == 0
    assert CALLS == [(first["method"], first["seed"])]  # that run only, the intact ones not
    assert "line 1: damaged row set aside" in capsys.readouterr().err
    keys = [(json.loads(x)["method"], json.loads(x)["seed"])
            for x in rows_file.read_text().splitlines()]
    assert sorted(keys) == sorted(FAKE_ENDS)  # one row each, none twice
    assert (tmp_path / "loop-runs" / "loop.rows.damaged").read_text().startswith("\x00garbled")
    CALLS.clear()
    assert main([*CAMPAIGN, "--json", str(out), "--resume"]) == 0
    assert CALLS == [] and len(rows_file.read_text().splitlines()) == len(FAKE_ENDS)
