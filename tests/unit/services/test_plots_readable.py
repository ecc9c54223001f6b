"""Every plot of a run and of a campaign: each axis labelled, each line in a legend.

The figures are taken from matplotlib itself (the Figure each plot function saves), so the check
reads the axes' labels and legend entries rather than looking at pixels."""

import matplotlib.lines
import pytest

from mobigrasp.cosim.run_folder import read_trace
from mobigrasp.services import plots
from mobigrasp.services.campaign import CampaignConfig, run_campaign


@pytest.fixture
def saved_figures(monkeypatch):
    """Figures passed to plots._save, by file name, kept open for inspection."""
    figures = {}
    original = plots._save

    def keep(fig, folder, name):
        figures[name] = fig
        fig.tight_layout()
        fig.savefig(folder / name, dpi=40)
        return name

    monkeypatch.setattr(plots, "_save", keep)
    yield figures
    for fig in figures.values():
        plots.plt.close(fig)
    assert original is not None


def _style(line: matplotlib.lines.Line2D) -> tuple:
    return (str(line.get_color()), line.get_linestyle(), line.get_marker())


def check_readable(fig, name: str) -> None:
    """Every axis with something drawn has an x and a y label; every line is in the legend of
    its axes (by its label, or, for a repeated line such as a second state marker, by a legend
    entry drawn in the same colour, line style and marker)."""
    for ax in fig.axes:
        if not (ax.lines or ax.patches or ax.collections):
            raise AssertionError(f"{name}: an empty panel")
        assert ax.get_xlabel().strip() or ax.get_shared_x_axes().get_siblings(ax) != [ax], \
            f"{name}: axis without an x label"
        assert ax.get_ylabel().strip(), f"{name}: axis {ax.get_title()!r} without a y label"
        legend = ax.get_legend()
        entries = {t.get_text() for t in legend.get_texts()} if legend else set()
        styles = {_style(line) for line in ax.lines if line.get_label() in entries}
        for line in ax.lines:
            label = line.get_label()
            assert label in entries or _style(line) in styles, \
                f"{name}: line {label!r} ({_style(line)}) has no legend entry"
    bottom = [ax for ax in fig.axes if ax.get_xlabel().strip()]
    assert bottom, f"{name}: no x label at all"


def test_every_plot_of_a_run_is_readable(short_runs, saved_figures, tmp_path):
    made = set()
    for scenario, folder in short_runs.items():
        events = read_trace(folder / "trace.jsonl")
        for fn in plots.ALL:
            saved_figures.clear()
            name = fn(events, tmp_path)
            if name is None:
                continue
            made.add(name)
            check_readable(saved_figures[name], f"{scenario} {name}")
    # each kind of plot was drawn by at least one of the three methods
    assert made == {"trajectory.png", "joints.png", "bezier.png", "fuzzy.png", "arm9_load.png"}


def test_trajectory_state_labels_are_not_piled_up(short_runs, saved_figures, tmp_path):
    events = read_trace(short_runs["paper000-exp1"] / "trace.jsonl")
    plots.trajectory(events, tmp_path)
    ax = saved_figures["trajectory.png"].axes[0]
    states = [e for e in events if e["ev"] == "state"]
    texts = [t for t in ax.texts if t.get_text().endswith(tuple(e["to"] for e in states))]
    assert len(texts) == len(states) >= 4
    # labels anchored at the same point (the robot stands while grasping) differ in offset
    spots = {}
    for t in texts:
        spots.setdefault(tuple(round(v, 3) for v in t.xy), []).append(tuple(t.xyann))
    for offsets in spots.values():
        assert len(set(offsets)) == len(offsets)
    assert max(len(v) for v in spots.values()) >= 2  # the case is in this run


def test_gripper_has_its_own_axis(short_runs, saved_figures, tmp_path):
    plots.joints(read_trace(short_runs["paper000-exp1"] / "trace.jsonl"), tmp_path)
    fig = saved_figures["joints.png"]
    by_axis = {ax.get_ylabel(): {line.get_label() for line in ax.lines} for ax in fig.axes}
    assert plots.JOINT_NAMES[0] not in by_axis["angle (rad)"]
    assert any(plots.JOINT_NAMES[0] in labels for name, labels in by_axis.items()
               if name.startswith("gripper"))


def _fake_run(job: dict) -> dict:
    seed = job["seed"]
    return {"status": "finished", "success": seed % 2 == 0, "task_state": "DONE",
            "sim_time_s": 5.0, "contacts": 0, "protocol": {"retransmits": seed},
            "safety": {"unsafe_actuations": seed % 3, "watchdog_trips": seed % 2,
                       "stop_latency_ms": [200.0 + seed] if seed % 2 else [],
                       "recovery_ms": [], "unrecovered": 0}}


@pytest.mark.parametrize("with_stops", [True, False])
def test_campaign_plot_is_readable(tmp_path, saved_figures, with_stops):
    def run(job):
        summary = _fake_run(job)
        if not with_stops:
            summary["safety"]["stop_latency_ms"] = []
        return summary

    result = run_campaign(CampaignConfig("000", 5, seed=3, jobs=1, out=tmp_path), run_fn=run)
    plots.campaign(result, tmp_path)
    fig = saved_figures["campaign.png"]
    check_readable(fig, "campaign.png")
    assert len(fig.axes) == (3 if with_stops else 2)  # no empty panel
    fig.canvas.draw()
    for ax in fig.axes:
        ticks = [t for t in ax.get_yticks() if ax.get_ylim()[0] <= t <= ax.get_ylim()[1]]
        assert all(float(t).is_integer() for t in ticks), f"fractional counts on {ax.get_ylabel()}"
    seeds_ax = next(ax for ax in fig.axes if ax.get_xlabel() == "seed")
    lo, hi = seeds_ax.get_xlim()
    ticks = [t for t in seeds_ax.get_xticks() if lo <= t <= hi]
    assert ticks and all(float(t).is_integer() and 3 <= t <= 7 for t in ticks)


def test_loop_campaign_plot_is_readable(tmp_path, saved_figures):
    from mobigrasp.services.loop_campaign import LoopCampaign
    from mobigrasp.services.loop_campaign import run_campaign as run_loop

    def run(job):
        seed = job["seed"]
        done = seed % 3 != 0
        return {"status": "finished", "success": done, "claimed_success": done,
                "grasped": done, "false_claim": False,
                "task_state": "DONE" if done else "FAILED", "end_reason": "task_done",
                "contacts": 0, "final_error_mm": 2.0 + seed % 5 if done else None,
                "sim_time_s": 20.0}

    cfg = LoopCampaign(methods=("000", "001"), runs=6, seed_base=3, jobs=1, out=tmp_path / "c")
    result = run_loop(cfg, run_fn=run)
    plots.loop_campaign(result, tmp_path / "loop.png")
    fig = saved_figures["loop.png"]
    check_readable(fig, "loop.png")
    outcome_ax = fig.axes[0]
    labels = {t.get_text() for t in outcome_ax.get_legend().get_texts()}
    assert labels == {"success (8)", "FAILED: no reason given (4)"}  # seeds 3 and 6 of each


def test_trajectory_draws_footprints_and_each_path_update_with_r_r_and_sonar(saved_figures,
                                                                              tmp_path):
    truth = [{"ev": "truth", "t_us": k * 100_000, "x_m": 0.1 * k, "y_m": 0.0,
              "heading_rad": 0.0, "obj": [3.0, 0.0, 0.0]} for k in range(31)]
    update = {"ev": "detail", "replan": "blocked: replanned", "plan": {"planner": "001"}}
    events = [{"ev": "start", "t_us": 0, "obstacles": []}, *truth,
              {**update, "t_us": 1_000_000}, {**update, "t_us": 2_000_000},
              {"ev": "detail", "t_us": 500_000, "plan": {"planner": "001"}},  # from standstill
              {"ev": "detail", "t_us": 600_000, "replan": "path clear"}]
    robot = {"footprint_m": 0.17, "safety_radius_m": 0.2,
             "sonar": {"k_s": 5, "A_g_rad": 1.05, "D_e_m": 2.5}}
    assert [e["t_us"] for e in plots.path_updates(events)] == [1_000_000, 2_000_000]
    assert plots.trajectory(events, tmp_path, {"robot": robot}) == "trajectory.png"
    ax = saved_figures["trajectory.png"].axes[0]
    check_readable(saved_figures["trajectory.png"], "trajectory")
    marks = [ln for ln in ax.lines if ln.get_marker() == "D"]
    assert [tuple(ln.get_xydata()[0]) for ln in marks] == [(1.0, 0.0), (2.0, 0.0)]
    circles = [p for p in ax.patches if isinstance(p, plots.Circle)]
    assert sum(abs(c.radius - 0.2) < 1e-9 for c in circles) == 2  # R_r at each update
    assert sum(abs(c.radius - 0.17) < 1e-9 for c in circles) == 7  # S, every 0.5 m, G
    assert sum(isinstance(p, plots.Wedge) for p in ax.patches) == 2 * 5
    assert "2 path updates" in ax.get_title()
    saved_figures.clear()
    plots.trajectory(events, tmp_path)  # without the summary: the path and updates only
    ax = saved_figures["trajectory.png"].axes[0]
    assert not any(isinstance(p, plots.Wedge | plots.Circle) for p in ax.patches)
