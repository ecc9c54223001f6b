"""Modelled against emulated ARM920T time, per host stage, over a frame corpus.

For each stage of :data:`STAGES` and each corpus frame given to a detector that runs it, the
modelled time is the stage's ``OpCounts`` from the Python kernel (host/budget.py constants) and
the emulated time is the same stage's C (hostc/) run as ARM920T code under calib/arm.py's
timing model; the emulated result is checked against the Python one on every frame. Per stage:
medians, p95, max, the ratio modelled / emulated, the instruction mix, CPI and the shares of
line fills and interlocks. The planning stages (:data:`PLANNING_STAGES`) run once per planner
call of the corpus's planning part (calib/plan_corpus.py, calib/planning.py) instead of per
frame.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Callable, Collection
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mobigrasp.calib import arm, corpus, plan_corpus, planning, program, timing
from mobigrasp.calib.native import red_roi_tuple
from mobigrasp.host import ranging
from mobigrasp.host.budget import FCLK_HZ
from mobigrasp.host.planning.anytime import CYCLES_PER_US, PLAN_SLICE_US
from mobigrasp.host.vision import dark_blobs, grey
from mobigrasp.host.vision.registry import DETECTORS
from mobigrasp.provenance import source_commit

# the detectors that start with dark_blobs.dark_components (grey, dark mask, labelling)
FRONT_END = ("radial_symbol", "dual_plus", "spoke", "radial_cut")
GREY_USERS = tuple(n for n, r in DETECTORS.items() if r.uses_grey)


@dataclass(frozen=True)
class StageDef:
    """A calibrated stage: the detectors whose frames it runs on."""

    name: str
    detectors: tuple[str, ...]


STAGES = (StageDef("grey", GREY_USERS),
          StageDef("dark_threshold", FRONT_END),
          StageDef("labelling", FRONT_END),
          # a detector's stage: its work after the front end, per call
          StageDef("radial_symbol", ("radial_symbol",)),
          # the radial symbol cut by the frame's border (000, 001 SEARCH): its component scan
          StageDef("radial_cut", ("radial_cut",)),
          StageDef("dual_plus", ("dual_plus",)),
          StageDef("spoke", ("spoke",)),
          # the 002 double cross: its work after the grey conversion, per call
          StageDef("double_cross", ("double_cross",)),
          # the 002 detector works on the RGB frame itself: the whole detector
          StageDef("red_cylinder", ("red_cylinder",)),
          # its colour ROI alone (steering without the rings): the whole detector
          StageDef("red_roi", ("red_roi",)),
          # the 002 ring-pair ranging after each red cylinder found (registry's ranging column)
          StageDef("ranging", ("red_cylinder",)))
# the Bezier candidate evaluation, per planner call of the planning corpus (not per frame)
PLANNING_STAGES = ("bezier000", "bezier001")
DETECTOR_STAGES = ("radial_symbol", "radial_cut", "dual_plus", "spoke", "double_cross",
                   "red_cylinder", "red_roi", "ranging")
# the planning stage of each method's planner
PLANNER_STAGE = {"000": "bezier000", "001": "bezier001"}


def stages_used(run_stages: dict, method: str | None) -> set[str]:
    """The calibrated stages a run used: those of the detectors it called, and its method's
    planner (a run's ``stages`` from summary.json)."""
    called = {k for k, v in run_stages.items() if (v or {}).get("calls")}
    used = {s.name for s in STAGES if called & set(s.detectors)}
    if method in PLANNER_STAGE:
        used.add(PLANNER_STAGE[method])
    return used


# (camera pitch, waist yaw) in mrad the ranging stage is given in turn: the corpus keeps the
# frames, not the joint angles; the ranging's cost depends on them only through its divisions'
# and roots' operand lengths
RANGING_POSES_MRAD = ((-300, 0), (-600, 250), (-150, -400))


def modelled_us(stage: str, height: int, width: int) -> float:
    """The cost model's time of a whole-frame stage (their counts depend on the size only)."""
    n = int(height) * int(width)
    ops = {"grey": lambda: grey.grey_cost(height, width),
           "dark_threshold": lambda: dark_blobs.dark_mask_cost(n),
           "labelling": lambda: dark_blobs.components_cost(n)}[stage]()
    return ops.cycles() * 1e6 / FCLK_HZ


def _python_stages(rgb: np.ndarray) -> dict[str, tuple[object, int]]:
    """Stage -> (result, modelled cycles) from the Python kernels."""
    g, g_ops = grey.to_grey(rgb)
    m, t, m_ops = dark_blobs.dark_mask(g)
    n, labels, stats, l_ops = dark_blobs.components(m)
    return {"grey": (g, g_ops.cycles()), "dark_threshold": ((m, t), m_ops.cycles()),
            "labelling": ((n, labels, stats), l_ops.cycles())}


def _same(a, b) -> bool:
    if isinstance(a, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(np.asarray(a), np.asarray(b))
    return a == b


def _spread(by_sc: dict[str, list[dict]], per_scenario: int | None) -> list[dict]:
    """All of each scenario's items, or ``per_scenario`` of them spread evenly (the same ones
    every time)."""
    out = []
    for items in by_sc.values():
        if per_scenario is None or len(items) <= per_scenario:
            out += items
        else:
            step = len(items) / per_scenario
            out += [items[int(k * step)] for k in range(per_scenario)]
    return out


def select_frames(index: dict, per_scenario: int | None,
                  scenarios: Collection[str] | None = None) -> list[dict]:
    """Corpus frames that some stage runs on: all, or ``per_scenario`` spread evenly over each
    scenario's (the same ones every time); only those of ``scenarios`` if given."""
    wanted = {d for s in STAGES for d in s.detectors}
    by_sc: dict[str, list[dict]] = {}
    for fr in index["frames"]:
        if (scenarios is None or fr["scenario"] in scenarios) and any(
                c["detector"] in wanted for c in fr["calls"]):
            by_sc.setdefault(fr["scenario"], []).append(fr)
    return _spread(by_sc, per_scenario)


def select_plans(index: dict, per_scenario: int | None,
                 scenarios: Collection[str] | None = None) -> list[dict]:
    """Planner calls of the planning corpus: all, or ``per_scenario`` spread evenly over each
    scenario's; only those of ``scenarios`` if given."""
    by_sc: dict[str, list[dict]] = {}
    for c in index["calls"]:
        if scenarios is None or c["scenario"] in scenarios:
            by_sc.setdefault(c["scenario"], []).append(c)
    return _spread(by_sc, per_scenario)


def plan_stage(machine: arm.Planner, st) -> tuple[str, bool, int, arm.Timing]:
    """One 000 planner call's candidate evaluation on the ARM920T: (stage, the result equals
    the Python's, modelled cycles, timing): the candidate set and the best, in one slice (a
    000 plan is charged in one control step)."""
    cp = st.coarse
    (best, reason, first, _), t = machine.bezier000(cp.ctrl, cp.n, cp.lim, st.k1, st.k2)
    ok = best == st.best and [plan_corpus.REASONS[r] for r in reason] == cp.reasons \
        and np.array_equal(first, cp.first)
    return "bezier000", ok, cp.cycles, t


def plan_slices(machine: arm.Planner, st: planning.Setup001,
                slice_cycles: int = PLAN_SLICE_US * CYCLES_PER_US
                ) -> tuple[bool, list[tuple[int, arm.Timing]]]:
    """One 001 planner call as the host runs it, an anytime computation in slices of the
    control steps (host/planning/anytime.py): slice k holds the plan's modelled cycles
    [k, k + 1) x ``slice_cycles``, its set-up first, then the coarse pass, the clearances and
    the fine check of eq. (18)'s pool. Each slice's kernel work runs as one call (or two: the
    end of the coarse pass and the start of the fine check), from a cold D-cache (vision and
    the control steps ran in between). Returns (the passes' results equal the Python's,
    [(modelled cycles, timing)] of each slice with kernel work)."""
    cp = st.coarse
    slices: dict[int, list] = {}

    def put(k: int, modelled: int, t: arm.Timing) -> None:
        row = slices.setdefault(k, [0, []])
        row[0] += modelled
        row[1].append(t)

    m = machine.start_pass(cp.ctrl, cp.lim, cp.geo)
    k = st.pre_coarse_cycles // slice_cycles
    taken = -1
    while taken < 0:
        begin = machine.pass_state()[0]
        taken, t = machine.bezier001_coarse_slice(
            m, cp.n, cp.n_reg, st.per_sample_cycles, st.setup_cycles, st.cut_cycles, st.k1,
            st.k2, (k + 1) * slice_cycles - st.pre_coarse_cycles)
        stop = machine.pass_state()[0] if taken < 0 else min(taken + 1, m)
        put(k, planning.coarse_cycles(st, begin, stop), t)
        k += 1 if taken < 0 else 0
    reason, first, cost = machine.coarse_outputs(m)
    evaluated = np.array([r != "budget" for r in cp.reasons])
    ok = [plan_corpus.REASONS[r] for r in reason] == cp.reasons \
        and np.array_equal(first[evaluated], cp.first[evaluated])
    order = planning.fine_order(cost, st.clearance, st.t_d_m, st.max_fine)
    pool = cp.ctrl[order]
    n_reg = len(st.fine_geo) // 12
    m = machine.start_pass(pool, st.fine_lim, st.fine_geo)
    k_fine = max(k, st.pre_fine_cycles // slice_cycles)
    got = -2
    while got == -2:
        begin = machine.pass_state()[0]
        (got, tried), t = machine.bezier001_fine_slice(
            m, st.n_fine, n_reg, st.per_sample_cycles, st.setup_cycles, st.worst_us,
            st.fine_budget_us, (k_fine + 1) * slice_cycles - st.pre_fine_cycles,
            cold=k_fine != k)
        stop = machine.pass_state()[0] if got == -2 else len(tried)
        put(k_fine, planning.fine_cycles(st, pool[begin:stop]), t)
        k_fine += 1
    chosen = None if got < 0 else (int(st.us[order[got]]), int(st.endpoints[order[got]]))
    ok = ok and chosen == st.best
    rows: list[list] = []
    for _, (mod, ts) in sorted(slices.items()):
        if mod or not rows:
            rows.append([mod, ts])
        else:  # a call charged nothing (an empty pool, the curve past the cut): the slice before
            rows[-1][1] = rows[-1][1] + ts
    return ok, [(mod, arm.Timing.sum(*ts)) for mod, ts in rows]


def _pct(values: list[float], q: float) -> float:
    return float(np.percentile(np.asarray(values, float), q)) if values else 0.0





def calibrate(folder: Path, per_scenario: int | None = 10,
              line_fill_cycles: int = timing.LINE_FILL_CYCLES, progress=None,
              on_step: Callable[[int, int, str], None] | None = None,
              record: Callable[[str], program.Recording] | None = None,
              scenarios: Collection[str] | None = None) -> dict:
    """The calibration result (JSON-able); see docs/budget.md for the fields. ``progress``:
    told what is being built (the ARM toolchain, once); ``on_step(done, total, what)``: after
    each frame and each planner call emulated, and each scenario replayed on the C program.
    ``record(scenario)``: a run of the Python host program recorded (services/corpus.py
    ``record_steps``), given: the shipped scenarios of each method the C program has are
    recorded after the corpus and replayed on the C program, their whole control steps and
    frame pipelines timed (calib/program.py: ``per_scenario`` of each kind a run).
    ``scenarios``: only the frames, planner calls and replays of these (default: all); a name
    the corpus does not hold is a :class:`corpus.CorpusError`."""
    index = corpus.read_index(folder)
    if scenarios is not None:
        held = {sc["name"] for sc in index["scenarios"]}
        missing = sorted(set(scenarios) - held)
        if missing:
            raise corpus.CorpusError(f"{folder}: no scenario {', '.join(missing)} in the corpus "
                                     f"(it holds {', '.join(sorted(held)) or 'none'})")
    frames = select_frames(index, per_scenario, scenarios)
    plans = (select_plans(plan_corpus.read_index(folder), per_scenario, scenarios)
             if (Path(folder) / plan_corpus.INDEX).is_file() else [])
    elf = program.build(progress) if record is not None else None
    runs = [sc for sc in program.scenarios_in_program(elf)
            if scenarios is None or sc in scenarios] if elf is not None else []
    steps = len(frames) + len(plans) + len(runs)
    machine = arm.Arm9(arm.build(progress), line_fill_cycles)
    front = arm.FrontEnd(machine)
    per: dict[str, dict[str, list]] = {name: {"mod": [], "emu": [], "t": []} for name in
                                       (*(s.name for s in STAGES), *PLANNING_STAGES)}
    mismatch = dict.fromkeys(per, 0)
    shape = None
    calls_by_file: dict[str, list[corpus.Call]] = {}
    for c in corpus.calls(folder, index):
        calls_by_file.setdefault(c.frame_file, []).append(c)

    def add(name, ok, modelled, t):
        if name not in per:
            per[name] = {"mod": [], "emu": [], "t": []}
            mismatch[name] = 0
        mismatch[name] += 0 if ok else 1
        if not t.cycles:  # a replay that parted from Python's: nothing timed
            return
        per[name]["mod"].append(modelled)
        per[name]["emu"].append(t.cycles)
        per[name]["t"].append(t)

    for k, fr in enumerate(frames):
        rgb = corpus.load_frame(folder, fr)
        h, w = rgb.shape[:2]
        shape = shape or [h, w]
        calls = calls_by_file.get(fr["file"], [])
        dets = {c.detector for c in calls}
        active = [s.name for s in STAGES if dets & set(s.detectors)
                  and s.name not in DETECTOR_STAGES]
        if active:
            py = _python_stages(rgb)
            emu = front.run(rgb, upto="labelling" if dets & set(FRONT_END) else "grey")
            for name in active:
                add(name, _same(emu[name][0], py[name][0]), py[name][1], emu[name][1])
        front_cycles = dark_blobs.front_end_min_ops(h, w).cycles()
        grey_cycles = grey.grey_cost(h, w).cycles()
        for c in calls:
            if c.detector == "radial_symbol":
                res, ops = DETECTORS["radial_symbol"].host_call(rgb, c.camera, None)
                got, t = front.radial_symbol(*c.camera)
                want = None if res is None else dataclasses.astuple(res)
                add("radial_symbol", got == want, ops.cycles() - front_cycles, t)
            elif c.detector == "radial_cut":
                res, ops = DETECTORS["radial_cut"].host_call(rgb, c.camera, None)
                got, t = front.radial_cut()
                want = None if res is None else dataclasses.astuple(res)
                add("radial_cut", got == want, ops.cycles() - front_cycles, t)
            elif c.detector == "dual_plus":
                q = c.args[0]
                res, ops = DETECTORS["dual_plus"].host_call(rgb, c.camera, q)
                got, t = front.dual_plus(int(q[2] + q[3] + q[4]), c.camera[0], c.camera[1])
                want = None if res is None else dataclasses.astuple(res)
                add("dual_plus", got == want, ops.cycles() - front_cycles, t)
            elif c.detector == "spoke":
                res, ops = DETECTORS["spoke"].host_call(rgb, c.camera, None)
                got, t = front.spoke()
                want = None if res is None else dataclasses.astuple(res)
                add("spoke", got == want, ops.cycles() - front_cycles, t)
            elif c.detector == "double_cross":
                q = c.args[0]
                res, ops = DETECTORS["double_cross"].host_call(rgb, c.camera, q)
                got, t = front.double_cross(int(q[5]), int(q[2] + q[3] + q[4]), c.camera[0])
                want = None if res is None else dataclasses.astuple(res)
                add("double_cross", got == want, ops.cycles() - grey_cycles, t)
            elif c.detector == "red_roi":
                res, ops = DETECTORS["red_roi"].host_call(rgb, c.camera, None)
                got, t = front.red_roi(rgb)
                want = None if res is None else red_roi_tuple(res)
                add("red_roi", got == want, ops.cycles(), t)
            elif c.detector == "red_cylinder":
                res, ops = DETECTORS["red_cylinder"].host_call(rgb, c.camera, None)
                got, t = front.red_cylinder(rgb)
                want = None if res is None else (*dataclasses.astuple(res)[:6], *res.roi)
                add("red_cylinder", got == want, ops.cycles(), t)
                if res is not None:
                    alpha, theta5 = RANGING_POSES_MRAD[len(per["ranging"]["emu"])
                                                       % len(RANGING_POSES_MRAD)]
                    fix = ranging.locate_ring_pair(res.d_pixel_q4, res.u_c_q4, res.v_c_q4,
                                                   res.width_q4, alpha, theta5, *c.camera)
                    got, t = front.locate_ring_pair(res.d_pixel_q4, res.u_c_q4, res.v_c_q4,
                                                    res.width_q4, alpha, theta5, *c.camera,
                                                    ranging.D_RING_UM)
                    add("ranging", got == dataclasses.astuple(fix),
                        DETECTORS["red_cylinder"].ranging_fn()().cycles(), t)
        if on_step is not None:
            on_step(k + 1, steps, f"frame {fr['file']}")
    plans_001: list[tuple[int, int, int]] = []  # (modelled, emulated cycles, slices) a plan
    if plans:
        plan_machine = arm.Planner(machine)
        for k, call in enumerate(plans):
            arrays = plan_corpus.load_arrays(folder, call)
            if not len(arrays["ctrl"]):
                pass
            elif isinstance(st := planning.setup(call, arrays), planning.Setup000):
                add(*plan_stage(plan_machine, st))
            else:
                ok, rows = plan_slices(plan_machine, st)
                for modelled, t in rows:
                    add("bezier001", ok, modelled, t)
                plans_001.append((sum(r[0] for r in rows), sum(r[1].cycles for r in rows),
                                  len(rows)))
            if on_step is not None:
                on_step(len(frames) + k + 1, steps, f"planner call {call['file']}")
    for k, scenario in enumerate(runs):
        for row in program.program_steps(elf, record(scenario), per_scenario, line_fill_cycles):
            add(*row)
        if on_step is not None:
            on_step(len(frames) + len(plans) + k + 1, steps,
                    f"{scenario} recorded and replayed on the C program")
    us = 1e6 / FCLK_HZ
    stages = {}
    for name, d in per.items():
        if not d["emu"]:
            if mismatch[name]:  # replays that parted from Python's, nothing timed
                stages[name] = {"frames": 0, "result_mismatches": mismatch[name], **dict.fromkeys(
                    ("modelled_median_us", "modelled_max_us", "emulated_median_us",
                     "emulated_p95_us", "emulated_max_us", "ratio_median", "ratio_min",
                     "ratio_max", "cpi", "line_fill_share"), 0)}
            continue
        ts = d["t"]
        instr = sum(t.instructions for t in ts)
        cyc = sum(t.cycles for t in ts)
        mix = {c: round(sum(t.mix[c] for t in ts) / instr, 4) for c in timing.CLASSES}
        ratios = [m / e for m, e in zip(d["mod"], d["emu"], strict=True)]
        stages[name] = {
            "frames": len(ts),
            "modelled_median_us": round(_pct(d["mod"], 50) * us, 1),
            "modelled_max_us": round(max(d["mod"]) * us, 1),
            "emulated_median_us": round(_pct(d["emu"], 50) * us, 1),
            "emulated_p95_us": round(_pct(d["emu"], 95) * us, 1),
            "emulated_max_us": round(max(d["emu"]) * us, 1),
            "ratio_median": round(_pct(ratios, 50), 3),
            "ratio_min": round(min(ratios), 3), "ratio_max": round(max(ratios), 3),
            "cpi": round(cyc / instr, 3),
            "instructions_median": int(_pct([t.instructions for t in ts], 50)),
            "mix": mix,
            "line_fill_share": round(sum(t.fill_cycles for t in ts) / cyc, 4),
            "interlock_share": round(sum(t.interlock_cycles for t in ts) / cyc, 4),
            "taken_branch_share": round(2 * sum(t.taken_branches for t in ts) / cyc, 4),
            "read_miss_rate": round(sum(t.read_misses for t in ts)
                                    / max(1, sum(t.reads for t in ts)), 4),
            "result_mismatches": mismatch[name],
        }
    if plans_001:  # bezier001's calls are slices: the whole plans beside them
        stages["bezier001"].update({
            "plans": len(plans_001),
            "plan_slices_max": max(p[2] for p in plans_001),
            "plan_modelled_max_us": round(max(p[0] for p in plans_001) * us, 1),
            "plan_emulated_median_us": round(_pct([p[1] for p in plans_001], 50) * us, 1),
            "plan_emulated_max_us": round(max(p[1] for p in plans_001) * us, 1)})
    commit = source_commit(("host", "hostc", "calib"), digits=12)
    return {"format": "mobigrasp-calibration/1", "commit": commit, "corpus": str(folder),
            "fclk_hz": FCLK_HZ, "line_fill_cycles": int(line_fill_cycles),
            "frames_per_scenario": per_scenario, "frames": len(frames), "frame_shape": shape,
            "stages": stages}


def default_path() -> Path:
    """Where the last calibration is kept for ``mobigrasp profile``."""
    from mobigrasp.calib.native import cache_dir

    return cache_dir() / "calibration.json"


def write(result: dict, path: Path | None = None) -> Path:
    """Write ``result`` as JSON (atomically) to ``path`` or :func:`default_path`."""
    path = Path(path) if path is not None else default_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + f".tmp{os.getpid()}")
    tmp.write_text(json.dumps(result, indent=2, sort_keys=True) + "\n")
    tmp.replace(path)
    return path


def load_last(path: Path | None = None) -> dict | None:
    """The last calibration written, or None when there is none (or it is unreadable)."""
    path = Path(path) if path is not None else default_path()
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or not isinstance(data.get("stages"), dict):
        return None
    return data
