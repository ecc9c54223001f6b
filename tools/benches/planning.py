"""``mobigrasp bench planning``: wall and modelled ARM9 time of one plan of 000 and of 001.

000: one full candidate set (start 2.0 m from the object, moving, object off to the side).
001: one plan with obstacles (three sonar echoes, object 3.2 m away) and, for comparison, one in
free space. Wall time is the median over ``--runs`` repetitions (target: <= 10 ms), with
the median process-CPU time next to it (on a loaded machine the wall time also counts waiting); the
modelled ARM9 time is the soft-float cost model of host.budget (target <= 100 ms per plan).
Also the fuzzy controller's integer step and the path follower's step, for scale.
"""

from __future__ import annotations

import statistics
import time

NAME = "planning"
HELP = "Bezier planning of 000 and 001: median wall ms and modelled ARM9 ms per plan"

SONAR_OBSTACLES = (2500, 1400, 2500, 1800, 2100)
SONAR_CLEAR = (2500, 2500, 2500, 2500, 2500)


def add_arguments(parser) -> None:
    """Options of the planning bench."""
    from mobigrasp.mcu_sim import checks

    parser.add_argument("--runs", type=checks.arg_int(50, 1_000_000),
                        default=60, help="repetitions per case (>= 50)")


def _median_ms(fn, runs: int) -> tuple[float, float, object]:
    """Median wall ms and median process-CPU ms (less sensitive to other load on the machine)."""
    out = fn()  # warm caches (grasp circle scan, numpy dispatch) outside the timing
    wall, cpu = [], []
    for _ in range(runs):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        cpu.append((time.process_time() - c0) * 1e3)
        wall.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(wall), statistics.median(cpu), out


def _plan_figures(prefix: str, timing: tuple[float, float], plan) -> dict:
    cands = plan.candidates
    return {
        f"{prefix}_wall_median_ms": round(timing[0], 3),
        f"{prefix}_cpu_median_ms": round(timing[1], 3),
        f"{prefix}_arm9_ms": plan.ops.time_us() / 1000.0,
        f"{prefix}_candidates": len(cands),
        f"{prefix}_feasible": int(cands.feasible_indices().size),
        f"{prefix}_samples_per_curve": plan.n_samples,
        f"{prefix}_candidate_stride": plan.stride,
        f"{prefix}_float_ops": plan.ops.float_ops,
        f"{prefix}_float_divs": plan.ops.float_divs,
        f"{prefix}_found": plan.best is not None,
    }


def run(args) -> dict:
    """Time the planners; figures with units in their names."""
    from mobigrasp.host.control.fuzzy import FuzzyController
    from mobigrasp.host.control.path_follow import PathFollower, Trajectory
    from mobigrasp.host.odometry import Pose
    from mobigrasp.host.planning.bezier000 import plan_000
    from mobigrasp.host.planning.bezier001 import plan_001

    runs = max(50, int(getattr(args, "runs", 60)))
    res: dict = {"runs": runs}
    *ms, p000 = _median_ms(lambda: plan_000((0.0, 0.0), (0.12, 0.0), (1.6, 1.2)), runs)
    res.update(_plan_figures("plan000", ms, p000))
    *ms, p001 = _median_ms(lambda: plan_001((0.0, 0.0), (0.2, 0.0), 0.0, (3.0, 1.1),
                                            SONAR_OBSTACLES), runs)
    res.update(_plan_figures("plan001_obstacles", ms, p001))
    res["plan001_obstacles_regions"] = len(p001.extra.get("regions", []))
    *ms, p001c = _median_ms(lambda: plan_001((0.0, 0.0), (0.2, 0.0), 0.0, (3.0, 1.1),
                                             SONAR_CLEAR), runs)
    res.update(_plan_figures("plan001_free", ms, p001c))

    ctl = FuzzyController()
    t0 = time.perf_counter()
    n = 0
    for e in range(-1500, 1501, 25):
        for ec in range(-5000, 5001, 500):
            ctl.u_mrad(e, ec)
            n += 1
    res["fuzzy_step_wall_us"] = round((time.perf_counter() - t0) / n * 1e6, 2)

    if p000.best is not None:
        traj = Trajectory.from_curve(p000.best)
        fol = PathFollower(traj, 0, 250)
        pose = Pose(10_000, -5_000, 20, 100, 0)
        t0 = time.perf_counter()
        for k in range(1000):
            fol.step(k * 20_000, pose)
        res["follow_step_wall_us"] = round((time.perf_counter() - t0) * 1e3, 2)
        res["trajectory_table_arm9_us"] = traj.ops.time_us()
    return res
