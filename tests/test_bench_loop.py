"""``mobigrasp bench loop --runs 0``: real-time factors over both transports at both lags."""

import json

from tools.cli import main


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
