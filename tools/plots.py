"""Plots of a run from its trace (matplotlib, Agg backend): the figures of the papers.

- trajectory.png: base trajectory with start S and end G, the object, obstacles (Fig. 7b/9b of 000,
  Fig. 7/8 of 001);
- joints.png: joint angles over time (Fig. 7a/9a of 000);
- bezier.png: candidate and chosen Bezier paths of every plan (Fig. 6 of 001);
- fuzzy.png: e, e_c and u of the fuzzy controller over time (002);
- arm9_load.png: modelled ARM9 load per window.
Each function returns the file name it wrote, or None when the trace has nothing to plot.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Circle, Polygon  # noqa: E402

JOINT_NAMES = ["θ0 gripper", "θ1 roll", "θ2 wrist", "θ3 elbow", "θ4 shoulder", "θ5 waist"]


def _save(fig, folder: Path, name: str) -> str:
    fig.tight_layout()
    fig.savefig(folder / name, dpi=90)
    plt.close(fig)
    return name


def _obstacles(ax, start: dict | None) -> None:
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
            ax.plot([o["x_m"], o["x2_m"]], [o["y_m"], o["y2_m"]], color="grey", lw=3)


def trajectory(events: list[dict], folder: Path) -> str | None:
    """Base trajectory with S and G (Fig. 7b/9b of 000)."""
    truth = [e for e in events if e["ev"] == "truth" and e.get("x_m") is not None]
    if not truth:
        return None
    start = next((e for e in events if e["ev"] == "start"), None)
    fig, ax = plt.subplots(figsize=(6, 5))
    _obstacles(ax, start)
    xs, ys = [e["x_m"] for e in truth], [e["y_m"] for e in truth]
    ax.plot(xs, ys, "b-", lw=1.5, label="base (truth)")
    ax.plot(xs[0], ys[0], "ks")
    ax.annotate("S", (xs[0], ys[0]), textcoords="offset points", xytext=(-12, -12))
    ax.plot(xs[-1], ys[-1], "k^")
    ax.annotate("G", (xs[-1], ys[-1]), textcoords="offset points", xytext=(6, 6))
    objs = [e["obj"] for e in truth if e.get("obj")]
    if objs:
        ax.plot([o[0] for o in objs], [o[1] for o in objs], "r:", lw=1)
        ax.plot(objs[0][0], objs[0][1], "r*", ms=12, label="object")
    for e in (e for e in events if e["ev"] == "state"):
        i = min(range(len(truth)), key=lambda k: abs(truth[k]["t_us"] - e["t_us"]))
        ax.annotate(str(e.get("to", ""))[:8], (xs[i], ys[i]), fontsize=6, color="green")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("Trajectory of the mobile platform")
    return _save(fig, folder, "trajectory.png")


def joints(events: list[dict], folder: Path) -> str | None:
    """Joint angles over time (Fig. 7a/9a of 000)."""
    truth = [e for e in events if e["ev"] == "truth" and e.get("joints_rad")]
    if not truth:
        return None
    t = [e["t_us"] / 1e6 for e in truth]
    fig, ax = plt.subplots(figsize=(7, 4))
    for j in range(1, 6):
        ax.plot(t, [e["joints_rad"][j] for e in truth], label=JOINT_NAMES[j])
    ax.plot(t, [e["joints_rad"][0] for e in truth], "k--", lw=0.8, label=JOINT_NAMES[0])
    for e in (e for e in events if e["ev"] == "state"):
        ax.axvline(e["t_us"] / 1e6, color="grey", lw=0.5, ls=":")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("angle (rad)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=3)
    ax.set_title("Joint angles")
    return _save(fig, folder, "joints.png")


def cubic_points(ctrl: list, n: int = 40) -> list[tuple[float, float]]:
    """Points of the cubic Bezier with control points ``ctrl`` ([x, y(, t)] each), eq. (4) of
    000 with the Bernstein basis."""
    (x0, y0), (x1, y1), (x2, y2), (x3, y3) = [(p[0], p[1]) for p in ctrl[:4]]
    out = []
    for i in range(n + 1):
        t = i / n
        b0, b1, b2, b3 = (1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t * t * (1 - t), t ** 3
        out.append((b0 * x0 + b1 * x1 + b2 * x2 + b3 * x3, b0 * y0 + b1 * y1 + b2 * y2 + b3 * y3))
    return out


def _curves(plan: dict, key: str) -> list[list[tuple[float, float]]]:
    """Poly-lines of a plan entry: sampled paths, or control points of cubic Beziers."""
    value = plan.get(key)
    if not isinstance(value, list) or not value:
        return []
    if all(isinstance(p, list) and len(p) >= 2 and isinstance(p[0], int | float) for p in value):
        return [cubic_points(value)] if len(value) == 4 else [[(p[0], p[1]) for p in value]]
    out = []
    for item in value:
        out.extend(_curves({"c": item}, "c"))
    return out


def _odom_to_world(start: dict | None):
    """The host plans in its odometry frame (the start pose); map to the world for plotting."""
    x0, y0, h0 = (start or {}).get("robot", [0.0, 0.0, 0.0])
    c, s = math.cos(h0), math.sin(h0)
    return lambda p: (x0 + c * p[0] - s * p[1], y0 + s * p[0] + c * p[1])


def bezier(events: list[dict], folder: Path) -> str | None:
    """Candidate (thin) and chosen (thick) Bezier paths of every plan in the trace."""
    plans = [e for e in events if e["ev"] == "detail" and isinstance(e.get("plan"), dict)]
    if not plans:
        return None
    fig, ax = plt.subplots(figsize=(6, 5))
    start = next((e for e in events if e["ev"] == "start"), None)
    _obstacles(ax, start)
    to_world = _odom_to_world(start)
    for k, e in enumerate(plans):
        plan = e["plan"]
        cands = _curves(plan, "candidates_ctrl") or _curves(plan, "candidates")
        best = _curves(plan, "best_ctrl") or _curves(plan, "best")
        pts = [p for path in cands + best for p in path]
        scale = 1e-3 if pts and max(abs(v) for p in pts for v in p) > 50 else 1.0  # mm or m
        cands = [[to_world((p[0] * scale, p[1] * scale)) for p in path] for path in cands]
        best = [[to_world((p[0] * scale, p[1] * scale)) for p in path] for path in best]
        for path in cands:
            ax.plot([p[0] for p in path], [p[1] for p in path], color="tab:red",
                    lw=0.4, alpha=0.4)
        for path in best:
            ax.plot([p[0] for p in path], [p[1] for p in path], color="tab:blue",
                    lw=2 if k == len(plans) - 1 else 1, alpha=1.0 if k == len(plans) - 1 else 0.5,
                    label="chosen (last plan)" if k == len(plans) - 1 else None)
    truth = [e for e in events if e["ev"] == "truth" and e.get("x_m") is not None]
    if truth:
        ax.plot([e["x_m"] for e in truth], [e["y_m"] for e in truth], "k:", lw=1, label="base")
        obj = truth[0].get("obj")
        if obj:
            ax.plot(obj[0], obj[1], "r*", ms=12, label="object")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title(f"Bezier paths ({len(plans)} plan(s); candidates red, chosen blue)")
    return _save(fig, folder, "bezier.png")


def fuzzy(events: list[dict], folder: Path) -> str | None:
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
        ax.plot(t, [e["fuzzy"].get(key) for e in rows], lw=1)
        ax.set_ylabel(key)
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel("t (s)")
    axes[0, 0].set_title("Fuzzy approaching (002): " + ", ".join(keys))
    return _save(fig, folder, "fuzzy.png")


def arm9_load(events: list[dict], folder: Path) -> str | None:
    """Modelled ARM9 load per window over the run."""
    rows = [e for e in events if e["ev"] == "load"]
    if not rows:
        return None
    fig, ax = plt.subplots(figsize=(7, 3))
    ax.step([e["t_us"] / 1e6 for e in rows], [e["load"] for e in rows], where="post")
    ax.axhline(1.0, color="red", lw=0.8, ls="--")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("ARM9 load")
    ax.set_ylim(0, max(1.1, max(e["load"] for e in rows) * 1.1))
    ax.grid(True, alpha=0.3)
    ax.set_title("Modelled ARM920T load (400 MHz)")
    return _save(fig, folder, "arm9_load.png")


ALL = (trajectory, joints, bezier, fuzzy, arm9_load)
