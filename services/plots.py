"""Plots of a run from its trace (matplotlib, Agg backend): the figures of the papers.

- trajectory.png: base trajectory with start S and end G, the object, obstacles, the robot's
  footprint along the way, and each path update where it happened with the safety circle R_r
  and the sonar regions R_v of 001 there (Fig. 7b/9b of 000, Fig. 7/8 of 001);
- joints.png: joint angles over time with the search, Bezier approach and adjustment stages
  shaded (Fig. 7a/9a of 000);
- bezier.png: candidate and chosen Bezier paths of every plan (Fig. 6 of 001);
- fuzzy.png: e, e_c and u of the fuzzy controller over time (002);
- arm9_load.png: modelled ARM9 load per window;
- campaign.png (of a campaign, not in ``ALL``): outcomes, unsafe actuations per seed, stop and
  recovery times;
- loop.png (of ``bench loop``'s campaign, not in ``ALL``): outcomes and final errors per method.
Each function of ``ALL`` takes the trace's events, the folder and the run's summary (its
``robot`` block: footprint, R_r, sonar ring; None draws without them) and returns the file name
it wrote, or None when the trace has nothing to plot.
"""

from __future__ import annotations

import math
import statistics
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Circle, Polygon, Wedge  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

from mobigrasp.services.plan_paths import odom_to_world, plan_paths_world  # noqa: E402
from mobigrasp.services.run_outcome import outcome  # noqa: E402

JOINT_NAMES = ["θ0 gripper", "θ1 roll", "θ2 wrist", "θ3 elbow", "θ4 shoulder", "θ5 waist"]


def _save(fig, folder: Path, name: str) -> str:
    fig.tight_layout()
    fig.savefig(folder / name, dpi=90)
    plt.close(fig)
    return name


def _obstacles(ax, start: dict | None) -> None:
    wall_label = "wall"
    for o in (start or {}).get("obstacles", []):
        if o.get("shape") == "circle":
            ax.add_patch(Circle((o["x_m"], o["y_m"]), o["radius_m"], color="grey", alpha=0.6))
        elif o.get("shape") == "box":
            c, s = math.cos(o["heading_rad"]), math.sin(o["heading_rad"])
            w, d = o["width_m"] / 2, o["depth_m"] / 2
            pts = [(o["x_m"] + c * x - s * y, o["y_m"] + s * x + c * y)
                   for x, y in ((-w, -d), (w, -d), (w, d), (-w, d))]
            ax.add_patch(Polygon(pts, color="grey", alpha=0.6))
        elif o.get("shape") == "wall":
            ax.plot([o["x_m"], o["x2_m"]], [o["y_m"], o["y2_m"]], color="grey", lw=3,
                    label=wall_label)
            wall_label = None


FOOTPRINT_EVERY_M = 0.5  # the footprint drawn along the path this far apart
SONAR_DRAW_M = 0.8  # the sonar regions drawn this far out (D_e = 2.5 m would cover the plot)


def path_updates(events: list[dict]) -> list[dict]:
    """The detail events of a new curve adopted while one was followed (docs/task.md)."""
    return [e for e in events if e["ev"] == "detail" and e.get("plan") is not None
            and e.get("replan") is not None]


def _footprints(ax, xs: list, ys: list, radius_m: float) -> None:
    """The robot's footprint at S, at G and every ``FOOTPRINT_EVERY_M`` of path."""
    done, label = -math.inf, "footprint"
    travelled = 0.0
    for k in range(len(xs)):
        if k:
            travelled += math.hypot(xs[k] - xs[k - 1], ys[k] - ys[k - 1])
        if travelled - done >= FOOTPRINT_EVERY_M or k in (0, len(xs) - 1):
            ax.add_patch(Circle((xs[k], ys[k]), radius_m, fill=False, color="tab:blue",
                                lw=0.6, alpha=0.5, label=label))
            label, done = None, travelled


def _update_marks(ax, events: list[dict], truth: list[dict], robot: dict) -> None:
    """Each path update where it happened, numbered, with the safety circle R_r and the sonar
    regions R_v (k_s cones of A_g, 001 §III.C.2) around the robot there."""
    sonar, r_r = robot.get("sonar") or {}, robot.get("safety_radius_m")
    label = {"update": "path update", "r": "safety circle R_r", "s": "sonar regions R_v"}
    for n, e in enumerate(path_updates(events), start=1):
        i = min(range(len(truth)), key=lambda k: abs(truth[k]["t_us"] - e["t_us"]))
        x, y, h = truth[i]["x_m"], truth[i]["y_m"], truth[i].get("heading_rad", 0.0)
        ax.plot(x, y, "D", color="tab:red", ms=4, label=label.pop("update", None))
        ax.annotate(str(n), (x, y), textcoords="offset points", xytext=(-10, 4), fontsize=6,
                    color="tab:red")
        if r_r:
            ax.add_patch(Circle((x, y), r_r, fill=False, ls="--", color="tab:red", lw=0.6,
                                label=label.pop("r", None)))
        k_s, a_g = sonar.get("k_s"), sonar.get("A_g_rad")
        if r_r and k_s and a_g:  # 001: the ring the planner sees with
            reach = min(SONAR_DRAW_M, sonar.get("D_e_m") or SONAR_DRAW_M)
            for k in range(k_s):
                phi = h - math.pi / 2 + k * math.pi / (k_s - 1)
                ax.add_patch(Wedge((x, y), reach, math.degrees(phi - a_g / 2),
                                   math.degrees(phi + a_g / 2), color="tab:orange", alpha=0.06,
                                   label=label.pop("s", None)))


def trajectory(events: list[dict], folder: Path, summary: dict | None = None) -> str | None:
    """Base trajectory with S and G, the footprint along it and the path updates (Fig. 7b/9b
    of 000, Fig. 7/8 of 001)."""
    truth = [e for e in events if e["ev"] == "truth" and e.get("x_m") is not None]
    if not truth:
        return None
    start = next((e for e in events if e["ev"] == "start"), None)
    robot = (summary or {}).get("robot") or {}
    fig, ax = plt.subplots(figsize=(6, 5))
    _obstacles(ax, start)
    xs, ys = [e["x_m"] for e in truth], [e["y_m"] for e in truth]
    if robot.get("footprint_m"):
        _footprints(ax, xs, ys, robot["footprint_m"])
    ax.plot(xs, ys, "b-", lw=1.5, label="base (truth)")
    ax.plot(xs[0], ys[0], "ks", label="start S")
    ax.annotate("S", (xs[0], ys[0]), textcoords="offset points", xytext=(-12, -12))
    ax.plot(xs[-1], ys[-1], "k^", label="end G")
    ax.annotate("G", (xs[-1], ys[-1]), textcoords="offset points", xytext=(6, 6))
    objs = [e["obj"] for e in truth if e.get("obj")]
    if objs:
        ax.plot([o[0] for o in objs], [o[1] for o in objs], "r:", lw=1, label="object path")
        ax.plot(objs[0][0], objs[0][1], "r*", ms=12, label="object")
    _update_marks(ax, events, truth, robot)
    _state_marks(ax, events, truth, xs, ys)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    n = len(path_updates(events))
    ax.set_title(f"Trajectory of the mobile platform ({n} path update{'s' * (n != 1)})")
    return _save(fig, folder, "trajectory.png")


LABEL_NEAR_M = 0.08  # state changes closer than this on the path share one stacked label column


def _state_marks(ax, events: list[dict], truth: list[dict], xs: list, ys: list) -> None:
    """A marker where the task changed state and its name beside it; labels of changes at
    nearly the same place (the robot stands still while grasping) stack upwards instead of
    being drawn over each other."""
    placed: list[tuple[float, float]] = []
    first = True
    for e in (e for e in events if e["ev"] == "state"):
        i = min(range(len(truth)), key=lambda k: abs(truth[k]["t_us"] - e["t_us"]))
        x, y = xs[i], ys[i]
        near = sum(math.hypot(x - px, y - py) < LABEL_NEAR_M for px, py in placed)
        placed.append((x, y))
        ax.plot(x, y, "o", color="green", ms=3, label="state change" if first else None)
        first = False
        ax.annotate(f"{e['t_us'] / 1e6:.1f} s {str(e.get('to', ''))}", (x, y),
                    textcoords="offset points", xytext=(6, -4 + 9 * near), fontsize=6,
                    color="green")


STAGES = {"SEARCH": ("object searching", "tab:olive"),
          "APPROACH": ("Bezier path based approaching", "tab:cyan"),
          "ADJUST": ("vision-based approaching adjustment", "tab:purple")}


def _stages(ax, events: list[dict], end_s: float) -> None:
    """The three stages of 000's Fig. 7(a) shaded where the task was in them (the task
    starts in the first change's ``from`` state)."""
    states = [e for e in events if e["ev"] == "state"]
    if states:
        states = [{"t_us": 0, "to": states[0].get("from")}, *states]
    seen = set()
    for k, e in enumerate(states):
        stage = STAGES.get(str(e.get("to")))
        if stage is None:
            continue
        t1 = states[k + 1]["t_us"] / 1e6 if k + 1 < len(states) else end_s
        ax.axvspan(e["t_us"] / 1e6, t1, color=stage[1], alpha=0.12,
                   label=None if stage[0] in seen else stage[0])
        seen.add(stage[0])


def joints(events: list[dict], folder: Path, summary: dict | None = None) -> str | None:
    """Joint angles over time, the stages shaded (Fig. 7a/9a of 000)."""
    truth = [e for e in events if e["ev"] == "truth" and e.get("joints_rad")]
    if not truth:
        return None
    t = [e["t_us"] / 1e6 for e in truth]
    fig, (ax, grip) = plt.subplots(2, 1, figsize=(7, 5), sharex=True,
                                   gridspec_kw={"height_ratios": [3, 1]})
    for j in range(1, 6):
        ax.plot(t, [e["joints_rad"][j] for e in truth], label=JOINT_NAMES[j])
    grip.plot(t, [e["joints_rad"][0] for e in truth], "k-", lw=1, label=JOINT_NAMES[0])
    _stages(ax, events, t[-1])
    states = [e for e in events if e["ev"] == "state"]
    for k, e in enumerate(states):
        for a in (ax, grip):
            a.axvline(e["t_us"] / 1e6, color="grey", lw=0.5, ls=":",
                      label="state change" if k == 0 else None)
        ax.annotate(str(e.get("to", "")), (e["t_us"] / 1e6, 1.0),
                    xycoords=("data", "axes fraction"), rotation=90, fontsize=6, color="grey",
                    va="top", ha="right")
    ax.set_ylabel("angle (rad)")
    grip.set_ylabel("gripper (0 open, 1 shut)")
    grip.set_ylim(-0.05, 1.05)
    grip.set_xlabel("t (s)")
    for a in (ax, grip):
        a.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=3)
    grip.legend(fontsize=7)
    ax.set_title("Variation of joint angles (stages shaded)")
    return _save(fig, folder, "joints.png")


def bezier(events: list[dict], folder: Path, summary: dict | None = None) -> str | None:
    """Candidate (thin) and chosen (thick) Bezier paths of every plan in the trace."""
    plans = [e for e in events if e["ev"] == "detail" and isinstance(e.get("plan"), dict)]
    if not plans:
        return None
    fig, ax = plt.subplots(figsize=(6, 5))
    start = next((e for e in events if e["ev"] == "start"), None)
    _obstacles(ax, start)
    to_world = odom_to_world(start)
    drawn_candidates = False
    for k, e in enumerate(plans):
        cands, best = plan_paths_world(e["plan"], to_world)
        for path in cands:
            ax.plot([p[0] for p in path], [p[1] for p in path], color="tab:red",
                    lw=0.4, alpha=0.4, label=None if drawn_candidates else "candidates")
            drawn_candidates = True
        for path in best:
            ax.plot([p[0] for p in path], [p[1] for p in path], color="tab:blue",
                    lw=2 if k == len(plans) - 1 else 1, alpha=1.0 if k == len(plans) - 1 else 0.5,
                    label="chosen (last plan)" if k == len(plans) - 1 else
                    "chosen (earlier plans)" if k == 0 else None)
    truth = [e for e in events if e["ev"] == "truth" and e.get("x_m") is not None]
    if truth:
        ax.plot([e["x_m"] for e in truth], [e["y_m"] for e in truth], "k:", lw=1, label="base")
        obj = truth[0].get("obj")
        if obj:
            ax.plot(obj[0], obj[1], "r*", ms=12, label="object")
    ax.set_xlabel("x (m, world)")
    ax.set_ylabel("y (m, world)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title(f"Bezier paths ({len(plans)} plan(s))")
    return _save(fig, folder, "bezier.png")


UNITS = {"mrad": "mrad", "mrad_s": "mrad/s", "mm": "mm", "mmps": "mm/s", "mm_s": "mm/s",
         "px": "px", "rad": "rad", "m": "m", "s": "s", "us": "µs", "ms": "ms"}


def split_unit(key: str) -> tuple[str, str]:
    """``e_c_mrad_s`` -> ("e_c", "mrad/s"): the name and the unit its suffix names ("" if
    none)."""
    for suffix in sorted(UNITS, key=len, reverse=True):
        if key.endswith("_" + suffix) and len(key) > len(suffix) + 1:
            return key[: -len(suffix) - 1], UNITS[suffix]
    return key, ""


def fuzzy(events: list[dict], folder: Path, summary: dict | None = None) -> str | None:
    """e, e_c and u of the fuzzy controller over time (002), whatever units the task logs."""
    rows = [e for e in events if e["ev"] == "detail" and isinstance(e.get("fuzzy"), dict)]
    if not rows:
        return None
    keys = []
    for want in ("e", "e_c", "u"):
        found = sorted(k for k in rows[0]["fuzzy"] if k == want or k.startswith(want + "_"))
        found = [k for k in found if not (want == "e" and k.startswith("e_c"))]
        keys += found[:1]
    keys = keys or [k for k, v in rows[0]["fuzzy"].items() if isinstance(v, int | float)][:3]
    if not keys:
        return None
    t = [e["t_us"] / 1e6 for e in rows]
    fig, axes = plt.subplots(len(keys), 1, figsize=(7, 1.8 * len(keys) + 1), sharex=True,
                             squeeze=False)
    for ax, key in zip(axes[:, 0], keys, strict=True):
        name, unit = split_unit(key)
        ax.plot(t, [e["fuzzy"].get(key) for e in rows], lw=1, label=name)
        ax.set_ylabel(f"{name} ({unit})" if unit else name)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
    axes[-1, 0].set_xlabel("t (s)")
    axes[0, 0].set_title("Fuzzy approaching (002): error e, its change e_c, output u")
    return _save(fig, folder, "fuzzy.png")


def arm9_load(events: list[dict], folder: Path, summary: dict | None = None) -> str | None:
    """Modelled ARM9 load per window over the run."""
    rows = [e for e in events if e["ev"] == "load"]
    if not rows:
        return None
    fig, ax = plt.subplots(figsize=(7, 3))
    ax.step([e["t_us"] / 1e6 for e in rows], [e["load"] for e in rows], where="post",
            label="load per window")
    ax.axhline(1.0, color="red", lw=0.8, ls="--", label="limit (100 % of the CPU)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("ARM9 load (fraction of 400 MHz)")
    ax.legend(fontsize=7, loc="upper right")
    ax.set_ylim(0, max(1.1, max(e["load"] for e in rows) * 1.1))
    ax.grid(True, alpha=0.3)
    ax.set_title("Modelled ARM920T load (400 MHz)")
    return _save(fig, folder, "arm9_load.png")


ALL = (trajectory, joints, bezier, fuzzy, arm9_load)


def campaign(result: dict, folder: Path) -> str:
    """campaign.png: outcome counts, unsafe actuations and watchdog trips per seed, and the
    wheel stop latencies and recovery times (that panel only when any were measured)."""
    agg, rows = result["summary"], result["rows"]
    stops = [v for r in rows for v in r["stop_latency_ms"]]
    recov = [v for r in rows for v in r["recovery_ms"]]
    fig, axes = plt.subplots(1, 3 if stops or recov else 2, figsize=(13 if stops or recov else 9,
                                                                     3.8), squeeze=False)
    axes = axes[0]
    ok, crashed = agg["successes"], agg["crashed_runs"]
    names = ["success", "failed", "crashed"]
    counts = [ok, agg["runs"] - ok - crashed, crashed]
    colours = ["tab:green", "tab:orange", "tab:red"]
    for name, count, colour in zip(names, counts, colours, strict=True):
        axes[0].bar([name], [count], color=colour, label=f"{name} ({count})")
    axes[0].set_ylabel("runs")
    axes[0].set_xlabel("outcome")
    axes[0].yaxis.set_major_locator(MaxNLocator(integer=True))
    axes[0].legend(fontsize=8)
    axes[0].set_title(f"outcome ({agg['success_rate'] * 100:.0f} % success)")
    seeds = [r["seed"] for r in rows]
    axes[1].bar(seeds, [r["unsafe_actuations"] for r in rows], width=0.6, color="tab:red",
                label="unsafe actuations")
    axes[1].plot(seeds, [r["watchdog_trips"] for r in rows], "k.", label="watchdog trips")
    axes[1].set_ylim(bottom=0, top=max([1] + [r["unsafe_actuations"] for r in rows]
                                       + [r["watchdog_trips"] for r in rows]) * 1.2)
    if seeds:
        axes[1].set_xlim(min(seeds) - 0.5, max(seeds) + 0.5)
    axes[1].xaxis.set_major_locator(MaxNLocator(integer=True))
    axes[1].yaxis.set_major_locator(MaxNLocator(integer=True))
    axes[1].set_xlabel("seed")
    axes[1].set_ylabel("count per run")
    axes[1].set_title("unsafe actuations, watchdog trips")
    axes[1].legend(fontsize=8)
    if stops or recov:
        axes[2].hist([stops, recov], bins=20, label=["wheel stop latency", "recovery"])
        axes[2].legend(fontsize=8)
        axes[2].set_xlabel("ms (simulated)")
        axes[2].set_ylabel("events")
        axes[2].yaxis.set_major_locator(MaxNLocator(integer=True))
        axes[2].set_title("stop latency / recovery time")
    return _save(fig, folder, "campaign.png")


OUTCOME_COLOURS = {"success": "tab:green", "board alone: FAILED": "tab:olive",
                   "false claim": "tab:red", "crashed": "black",
                   "success with contact": "tab:pink"}


def loop_campaign(result: dict, path: Path) -> str:
    """loop.png of ``mobigrasp bench loop``: the outcome of every run per method (success and
    each cause of failure) and the final error of every run that has one, per method."""
    methods = list(result["methods"])
    rows = result["rows"]
    found = {outcome(r) for r in rows}
    causes = [c for c in OUTCOME_COLOURS if c in found] + sorted(found - set(OUTCOME_COLOURS))
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2))
    others = iter(plt.get_cmap("tab20b").colors)
    left = [0] * len(methods)
    for cause in causes:
        counts = [sum(outcome(r) == cause for r in rows if r["method"] == m) for m in methods]
        axes[0].barh(methods, counts, left=left, label=f"{cause} ({sum(counts)})",
                     color=OUTCOME_COLOURS.get(cause) or next(others, "grey"))
        left = [a + b for a, b in zip(left, counts, strict=True)]
    axes[0].set_xlabel("runs")
    axes[0].set_ylabel("method")
    axes[0].xaxis.set_major_locator(MaxNLocator(integer=True))
    axes[0].legend(fontsize=7, loc="upper left", bbox_to_anchor=(0.0, -0.15), ncol=2)
    axes[0].set_title(f"outcome per method ({result['generator']}, {result['transport']}, "
                      f"{result['commit']})")
    errs = [[r["final_error_mm"] for r in rows if r["method"] == m
             and r.get("final_error_mm") is not None] for m in methods]
    for k, e in enumerate(errs):
        # each run a dot, spread sideways by its index so equal errors stay apart
        xs = [k + 0.3 * ((i % 7) / 6 - 0.5) for i in range(len(e))]
        axes[1].plot(xs, e, "k.", alpha=0.5, label="a run's final error" if k == 0 else None)
        if e:
            axes[1].plot([k], [statistics.median(e)], "_", color="tab:blue", markersize=30,
                         mew=2, label="median of the method" if k == 0 else None)
    axes[1].set_xticks(range(len(methods)), methods)
    axes[1].set_xlim(-0.5, len(methods) - 0.5)
    axes[1].axhline(10.0, color="tab:red", ls="--", lw=1, label="bar: median <= 10 mm")
    axes[1].set_xlabel("method")
    axes[1].set_ylabel("final error (mm)")
    axes[1].set_title("final error of every run that has one")
    axes[1].legend(fontsize=8, loc="upper right")
    path = Path(path)
    return _save(fig, path.parent, path.name)
