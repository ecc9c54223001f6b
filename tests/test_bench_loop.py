"""``mobigrasp bench loop --runs 0``: real-time factors over both transports at both lags."""

import json

from mobigrasp.tools.cli import main


def test_bench_loop_reports_rtf_against_the_strict_alternation_baseline(tmp_path):
    out = tmp_path / "loop.json"
    assert main(["bench", "loop", "--runs", "0", "--rtf-limit-s", "0.4", "--rtf-repeats", "2",
                 "--json", str(out)]) == 0
    fig = json.loads(out.read_text())
    for tag in ("pty", "inproc", "pty_lag0", "inproc_lag0"):
        runs = fig[f"realtime_factor_{tag}_runs"]
        assert len(runs) == 2 and all(r > 0 for r in runs)
        assert min(runs) <= fig[f"realtime_factor_{tag}"] <= max(runs)  # the median of them
        assert fig[f"sim_s_{tag}"] >= 0.4
        assert 0.0 < fig[f"wall_host_s_{tag}"] < fig[f"wall_s_{tag}"]
    assert fig["speedup_pty_vs_lag0"] == round(
        fig["realtime_factor_pty"] / fig["realtime_factor_pty_lag0"], 3)
    assert fig["trace_equal_pty_inproc"] is True
    assert "campaign" not in fig


def test_bench_loop_takes_the_four_configurations_in_turn(monkeypatch, tmp_path):
    """Run by run, not in blocks: the machine's speed drifts over minutes (tools/benches/loop)."""
    import mobigrasp.tools.benches.loop as loop
    order = []

    def fake_one(opts):
        order.append((opts.host_lag_quanta, opts.transport))
        wall = 1.0 + 0.1 * len(order)  # drifting: each run slower than the last
        return {"wall_time_s": wall, "sim_time_s": 17.0, "realtime_factor": 17.0 / wall,
                "wall_host_s": 0.5, "trace_sha256": f"sha{opts.host_lag_quanta}"}

    monkeypatch.setattr(loop, "_one", fake_one)
    out = tmp_path / "loop.json"
    assert main(["bench", "loop", "--runs", "0", "--rtf-repeats", "3", "--json", str(out)]) == 0
    configs = [(1, "pty"), (1, "inproc"), (0, "pty"), (0, "inproc")]
    assert order == configs * 3
    fig = json.loads(out.read_text())
    # the medians of interleaved runs: the 2nd of each configuration's three
    assert fig["wall_s_pty"] == round(1.0 + 0.1 * 5, 3)
    assert fig["wall_s_inproc_lag0"] == round(1.0 + 0.1 * 8, 3)


def test_random_scenes_give_the_same_trace_over_the_pty_and_in_process(tmp_path):
    """Two short random scenes (001 with obstacles and light faults, 002 with light faults)."""
    from mobigrasp.tools.benches.loop import _random_run

    for method, seed in (("001", 1009), ("002", 1004)):
        pty = _random_run(method, seed, tmp_path / "pty", transport="pty", time_limit_s=3.0)
        inproc = _random_run(method, seed, tmp_path / "inproc", transport="inproc",
                             time_limit_s=3.0)
        assert (pty["transport"], inproc["transport"]) == ("pty", "inproc")
        assert pty["sim_time_s"] >= 3.0 and pty["trace_lines"] > 10
        assert pty["trace_sha256"] == inproc["trace_sha256"], (method, seed)
