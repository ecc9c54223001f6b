"""001's replanner around the plan in C (hostc/replan.c) against host/planning/replan.py's
Replanner: the same remembered regions, the same check of the rest of the curve (blocked or
not, its modelled cost), the same curve, level and start time after each plan, the same
decision (a new curve, none, the old one kept), on hypothesis-drawn sequences of sonar
updates; the plans are the Python's (plan_001), given to the C as their outcome."""

from __future__ import annotations

import copy
import math
from collections import deque

import numpy as np
import pytest
from hypothesis import event, given
from hypothesis import strategies as st
from plan001_c import params_c
from property_examples import examples

from mobigrasp import hostc
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.control.path_follow import Trajectory
from mobigrasp.host.planning.bezier001 import Params001
from mobigrasp.host.planning.bezier_q import POS_PER_M, quantize_ctrl
from mobigrasp.host.planning.replan import Replanner
from mobigrasp.host.planning.sonar_regions import InfeasibleRegion, sonar_q
from mobigrasp.host.task.drive import state_m, velocity_m
from mobigrasp.host.task.method001 import escape_001, planner_params_001, straight_clear_001
from mobigrasp.host.task.params import TaskParams

FFI, C = hostc.lib()
NEW, STOP, KEPT = C.MG_REPLAN_NEW, C.MG_REPLAN_STOP, C.MG_REPLAN_KEPT


def _cfg(rp: Replanner):
    q = sonar_q(rp.params.sonar)
    return FFI.new("mg_replan001_cfg_t *", {
        "sonar": [q.k_s, q.a_g_urad, q.d_e_q4, q.r_r_q4, q.tol_q4, q.offset_q4,
                  int(q.arc_bound), q.cot_half_q12],
        "target_q4": [round(float(v) * POS_PER_M) for v in rp.target],
        "echo_tol_q4": round(rp.params.object_echo_tol_m * POS_PER_M),
        "memory": rp.memory.maxlen, "check_samples": rp.check_samples,
        "n_levels": len(rp.slow_factors), "keep_going_q4": round(rp.keep_going_m * POS_PER_M)})


def _ctrl(curve) -> list[int]:
    return [int(v) for v in quantize_ctrl(curve.array).ravel()]


def _same_state(st, rp: Replanner) -> None:
    memory = [InfeasibleRegion(r.ox_q4, r.oy_q4, r.lo_urad, r.hi_urad, r.eta_q4, r.r_r_q4,
                               bool(r.arc_bound)) for r in st.memory[0:st.n_memory]]
    assert memory == list(rp.memory)
    assert st.level == rp.level and st.replans == rp.replans
    assert bool(st.has_curve) == (rp.curve is not None)
    if rp.curve is not None:
        assert list(st.ctrl) == _ctrl(rp.curve) and st.start_us == rp.start_us


POSE = st.tuples(st.integers(-600, 600), st.integers(-600, 600), st.integers(-3141, 3141),
                 st.integers(0, 300))
SONAR = st.lists(st.one_of(st.integers(150, 2600), st.just(65535), st.just(-1)), min_size=5,
                 max_size=5)


@examples(25)
@given(st.tuples(st.integers(1500, 3500), st.integers(-800, 800)), SONAR,
       st.lists(st.tuples(st.integers(100_000, 2_000_000), POSE, SONAR, st.booleans()),
                min_size=1, max_size=4), st.booleans())
def test_replanner_updates_as_the_python(target_mm, sonar0, updates, default_task):
    params = planner_params_001(TaskParams.for_method("001")) if default_task else None
    rp = Replanner((target_mm[0] / 1000, target_mm[1] / 1000), params)
    cfg, s = _cfg(rp), FFI.new("mg_replan001_state_t *")
    C.mg_replan001_init(s)
    pos, h, vel = state_m(0, 0, 0, 200)
    plan = rp.start(0, pos, h, vel, sonar0)
    best = FFI.new("int32_t[12]", _ctrl(plan.best) if plan.best is not None else [0] * 12)
    s.level = 0
    C.mg_replan001_adopt(cfg, s, 0, 0, 0, 0, sonar0, plan.best is not None, best)
    _same_state(s, rp)
    t_us = 0
    for dt_us, (x_mm, y_mm, h_mrad, v_mmps), sonar, force in updates:
        t_us += dt_us
        pos, h, vel = state_m(x_mm, y_mm, h_mrad, v_mmps)
        dec = rp.update(t_us, pos, h, vel, sonar, force)
        chk = FFI.new("mg_replan001_check_t *")
        need = C.mg_replan001_check(cfg, s, t_us, x_mm * 16, y_mm * 16, h_mrad, sonar, force,
                                    chk)
        assert bool(need) == (dec.plan is not None)
        assert bool(chk.blocked) == dec.blocked
        plan_ops = dec.plan.ops.as_tuple() if dec.plan is not None else (0,) * 11
        assert hostc.ops_tuple(chk.ops) == tuple(
            a - b for a, b in zip(dec.ops.as_tuple(), plan_ops, strict=True))
        if need:
            has = dec.plan.best is not None
            best = FFI.new("int32_t[12]", _ctrl(dec.plan.best) if has else [0] * 12)
            why, ahead = FFI.new("int32_t *"), FFI.new("int64_t *")
            got = C.mg_replan001_after_plan(cfg, s, t_us, x_mm * 16, y_mm * 16, h_mrad, sonar,
                                            chk, has, best, why, ahead)
            want = NEW if dec.replanned else KEPT if dec.curve is not None else STOP
            event(f"decision {('new', 'stop', 'kept')[want]}, blocked {dec.blocked}")
            assert got == want, dec.reason
            text = ("blocked", "no path", "path dropped")[why[0]]
            assert got == KEPT or dec.reason.startswith(text)
            if got == KEPT:
                assert dec.reason.startswith(f"blocked {ahead[0] / POS_PER_M:.2f} m ahead")
        _same_state(s, rp)


def test_the_memory_keeps_the_newest_and_forgets_what_is_seen_again():
    """Capacity: the oldest forgotten first; a remembered echo whose middle is in view again
    is forgotten (forget_seen), one behind the ring kept."""
    rp = Replanner((3.0, 0.0), memory=3)
    cfg, s = _cfg(rp), FFI.new("mg_replan001_state_t *")
    C.mg_replan001_init(s)
    readings = [[65535, 900, 65535, 65535, 65535], [65535, 65535, 65535, 800, 65535],
                [700, 65535, 65535, 65535, 1100]]
    for i, sonar in enumerate(readings):
        x_mm = 400 * i
        pos, h, vel = state_m(x_mm, 0, 0, 200)
        plan = rp.start(i * 1_000_000, pos, h, vel, sonar)
        best = FFI.new("int32_t[12]", _ctrl(plan.best) if plan.best is not None else [0] * 12)
        s.level = 0
        C.mg_replan001_adopt(cfg, s, i * 1_000_000, x_mm * 16, 0, 0, sonar,
                             plan.best is not None, best)
        _same_state(s, rp)
    assert s.n_memory == 3  # four regions seen, the first forgotten
    for x_mm, h_mrad in ((800, 0), (800, 3142), (-2000, 0)):
        before = list(rp.memory)
        n_py = rp.forget_seen(state_m(x_mm, 0, h_mrad, 0)[0], h_mrad / 1000)
        assert C.mg_replan001_forget_seen(cfg, s, x_mm * 16, 0, h_mrad) == n_py
        _same_state(s, rp)
        rp.memory.extend(r for r in before if r not in rp.memory)  # the next pose: all again
        s.n_memory = 0
        for r in before:
            s.memory[s.n_memory] = [r.ox_q4, r.oy_q4, r.lo_urad, r.hi_urad, r.eta_q4, r.r_r_q4,
                                    int(r.arc_bound)]
            s.n_memory += 1
    assert np.any([rp.forget_seen((0.8, 0.0), 0.0) > 0])


def record_replans(mp, calls: list):
    """A recorder (test_hostc_task.recorded_runs) of every call of 001's replanner (start,
    update), with the replanner's state after it: the watcher that appends them to ``calls``."""
    from mobigrasp.host.planning.observe import watching

    def watch(name, args, kw, result):
        rp = args[0]
        calls.append((name, rp, args[1:], kw, result,
                      (list(rp.memory), rp.level, rp.replans,
                       None if rp.curve is None else _ctrl(rp.curve), rp.start_us)))
    return watching(watch, topic="replan")


def _replay(calls) -> dict:
    """The calls replayed on the C replanner, each replanner from its start; the outcomes."""
    seen: dict = {}
    counts: dict[str, int] = {}
    for name, rp, args, kw, result, after in calls:
        if id(rp) not in seen:
            s = FFI.new("mg_replan001_state_t *")
            C.mg_replan001_init(s)
            seen[id(rp)] = (_cfg(rp), s)
        cfg, s = seen[id(rp)]
        if name == "start_path":
            C.mg_replan001_start_path(s, args[0])
            assert s.start_us == after[4]
            continue
        t_us, pos, h, _vel, sonar = args[:5]
        px, py = round(pos[0] * POS_PER_M), round(pos[1] * POS_PER_M)
        h_mrad = round(h * 1000)
        if name == "start":
            best = result.best
            s.level = 0
            C.mg_replan001_adopt(cfg, s, t_us, px, py, h_mrad, list(sonar), best is not None,
                                 FFI.new("int32_t[12]", _ctrl(best) if best else [0] * 12))
            counts["start"] = counts.get("start", 0) + 1
        else:
            force = bool(args[5] if len(args) > 5 else kw.get("force", False))
            dec = result
            chk = FFI.new("mg_replan001_check_t *")
            need = C.mg_replan001_check(cfg, s, t_us, px, py, h_mrad, list(sonar), force, chk)
            assert bool(need) == (dec.plan is not None) and bool(chk.blocked) == dec.blocked
            kind = "clear"
            if need:
                best = dec.plan.best
                why, ahead = FFI.new("int32_t *"), FFI.new("int64_t *")
                got = C.mg_replan001_after_plan(
                    cfg, s, t_us, px, py, h_mrad, list(sonar), chk, best is not None,
                    FFI.new("int32_t[12]", _ctrl(best) if best else [0] * 12), why, ahead)
                kind = ("new", "stop", "kept")[got]
                assert kind == ("new" if dec.replanned else "kept" if dec.curve is not None
                                else "stop"), dec.reason
            counts[kind] = counts.get(kind, 0) + 1
        memory, level, replans, ctrl, start_us = after
        assert [(r.ox_q4, r.oy_q4, r.lo_urad, r.hi_urad, r.eta_q4, r.r_r_q4, bool(r.arc_bound))
                for r in s.memory[0:s.n_memory]] == [
            (r.ox_q4, r.oy_q4, r.lo_urad, r.hi_urad, r.eta_q4, r.r_r_q4, r.arc_bound)
            for r in memory]
        assert (s.level, s.replans, bool(s.has_curve)) == (level, replans, ctrl is not None)
        if ctrl is not None:
            assert list(s.ctrl) == ctrl and s.start_us == start_us
    return counts


@pytest.fixture
def sim1_calls(shared_recording) -> list:
    """paper001-sim1's replanner calls, from the session's one run of it (conftest.py; the
    replays only read them)."""
    return shared_recording("paper001-sim1", "replans")


def test_replay_of_paper001_sim1(sim1_calls):
    """Every replanner call the Python made in paper001-sim1, replayed on the C: the same
    checks, decisions, memory and curves, call by call."""
    counts = _replay(sim1_calls)
    assert counts.get("start", 0) >= 1 and counts.get("new", 0) >= 2, counts
    assert counts.get("clear", 0) > 20, counts


@pytest.mark.slow
def test_replay_of_paper001_sim2(shared_recording):
    """The same for paper001-sim2, whose far blocks keep the path while no update exists."""
    counts = _replay(shared_recording("paper001-sim2", "replans"))
    assert counts.get("new", 0) >= 5 and counts.get("kept", 0) >= 1, counts


def _board(rp: Replanner, base_v0: float):
    """The board's replanner (task_method001.c) with the replanner's parameters."""
    b = FFI.new("mg_board_replanner001_t *")
    b.params = params_c(rp.params)[0]
    b.cfg = _cfg(rp)[0]
    for i, f in enumerate(rp.slow_factors):
        b.level_v0_mm_s[i] = round(base_v0 * f * 1000)
    b.v_limit_mm_s = round(rp.params.v_max * 1000)
    return b


def _inputs(pos, h, vel, sonar):
    """The task's inputs the SI arguments were made from (drive.state_m)."""
    x_mm, y_mm, h_mrad = round(pos[0] * 1000), round(pos[1] * 1000), round(h * 1000)
    guess = round(math.hypot(*vel) * 1000)
    v_mmps = next(v for v in sorted(range(-guess - 3, guess + 4), key=abs)
                  if velocity_m(v, h_mrad) == tuple(vel))
    inp = FFI.new("mg_task_inputs_t *")
    inp.x_mm, inp.y_mm, inp.heading_mrad, inp.v_mmps = x_mm, y_mm, h_mrad, v_mmps
    inp.n_sonar = len(sonar)
    for i, r in enumerate(sonar):
        inp.sonar_mm[i] = r
    return inp


def _follower_ops(curve) -> OpCounts:
    return OpCounts() if curve is None else Trajectory.from_curve(curve).ops


def _same_escape(b, rp: Replanner, inp, obj_mm, detour_mm: int, side: int) -> str:
    """The board's escape_001 (its mg_replanner001_t) as method001.py's: the same heading or
    none, the same modelled cost; "found" or "none"."""
    ops, head = FFI.new("mg_ops_t *"), FFI.new("int32_t *")
    found = C.mg_board_replanner001.escape(b, inp, list(obj_mm), detour_mm, side, head, ops)
    want, want_ops = escape_001(rp, inp.x_mm, inp.y_mm, inp.heading_mrad,
                                tuple(inp.sonar_mm[0:inp.n_sonar]), tuple(obj_mm), detour_mm,
                                side)
    assert (head[0] if found else None) == want
    assert hostc.ops_tuple(ops[0]) == want_ops.as_tuple()
    return "found" if found else "none"


def _replay_board(calls, base_v0: float) -> dict:
    """The calls replayed on the board's replanner through its mg_replanner001_t: the same
    paths, reasons, decisions and modelled time; its straight-way test after each update as
    method001.py's."""
    table, boards, counts = C.mg_board_replanner001, {}, {}
    traj, o = FFI.new("mg_trajectory_t *"), FFI.new("mg_plan_outcome_t *")
    for name, rp, args, kw, result, after in calls:
        if name == "start":
            boards[id(rp)] = b = _board(rp, base_v0)
            inp = _inputs(*args[1:5])
            obj = FFI.new("int32_t[2]", [round(float(v) * 1000) for v in rp.target])
            table.start(b, args[0], inp, obj, round(base_v0 / rp.params.v0), traj, o)
            assert bool(o.has_path) == (result.best is not None)
            assert FFI.string(o.reason).decode() == result.reason
            assert o.time_us == (result.ops + _follower_ops(result.best)).time_us()
        elif name == "start_path":
            table.start_path(boards[id(rp)], args[0])
        else:
            b, dec = boards[id(rp)], result
            inp = _inputs(*args[1:5])
            force = bool(args[5] if len(args) > 5 else kw.get("force", False))
            c_dec, ops = FFI.new("mg_replan001_t *"), FFI.new("mg_ops_t *")
            table.update(b, args[0], inp, force, c_dec, traj, o, ops)
            assert (c_dec.blocked, c_dec.replanned, c_dec.has_curve, c_dec.has_plan) == (
                dec.blocked, dec.replanned, dec.curve is not None, dec.plan is not None)
            assert FFI.string(o.reason).decode() == dec.reason
            fol = _follower_ops(dec.curve if dec.replanned else None)
            assert hostc.ops_tuple(ops[0]) == (dec.ops + fol).as_tuple()
            assert bool(o.has_path) == bool(dec.replanned and dec.curve is not None)
            clear_ops = FFI.new("mg_ops_t *")
            obj_mm = [round(float(v) * 1000) for v in rp.target]
            got = table.straight_clear(b, inp, obj_mm, 800, clear_ops)
            then = copy.copy(rp)  # the replanner as this call left it (its memory)
            then.memory = deque(after[0], maxlen=rp.memory.maxlen)
            want, want_ops = straight_clear_001(then, inp.x_mm, inp.y_mm, inp.heading_mrad,
                                                tuple(inp.sonar_mm[0:inp.n_sonar]), obj_mm, 800)
            assert bool(got) == want and hostc.ops_tuple(clear_ops[0]) == want_ops.as_tuple()
            _same_escape(b, then, inp, obj_mm, 500, 0)
            name = "kept" if dec.blocked and dec.curve is not None and not dec.replanned \
                else name
        counts[name] = counts.get(name, 0) + 1
    return counts


def test_board_replanner_replays_paper001_sim1(sim1_calls):
    """The board's replanner (replan.c around plan001.c) gives every outcome the Python's
    replanner gave in paper001-sim1: the same paths, reasons and modelled time."""
    base_v0 = planner_params_001(TaskParams.for_method("001")).v0
    counts = _replay_board(sim1_calls, base_v0)
    assert counts.get("start", 0) >= 1 and counts.get("update", 0) > 20, counts


@pytest.mark.slow
def test_board_replanner_replays_paper001_sim2(shared_recording):
    """The same for paper001-sim2 (blocks far ahead keep the path, in words too)."""
    base_v0 = planner_params_001(TaskParams.for_method("001")).v0
    counts = _replay_board(shared_recording("paper001-sim2", "replans"), base_v0)
    assert counts.get("kept", 0) >= 1, counts


@examples(400)
@given(st.one_of(st.integers(0, 1 << 40), st.integers(0, 1 << 33).map(lambda k: 160 * k + 80)))
def test_metres_in_two_decimals_as_python_prints_them(q4):
    """The replanner's reason prints the block's distance as Python's .2f of q4 / 16000, also
    where the decimal tie is decided by the double's last bit."""
    buf = FFI.new("char[64]")
    C.mg_method001_text_m_2(buf, 64, 0, q4)
    assert FFI.string(buf).decode() == f"{q4 / POS_PER_M:.2f}"


@examples(20)
@given(st.tuples(st.integers(1500, 3500), st.integers(-800, 800)), SONAR,
       st.sampled_from([1, 2, 4]),
       st.lists(st.tuples(st.integers(100_000, 2_000_000), POSE, SONAR, st.booleans()),
                min_size=1, max_size=3), st.integers(100, 800), st.sampled_from([-1, 0, 1]),
       st.sampled_from([0.2, 0.25, 0.23, 0.3]))
def test_board_replanner_as_method001(target_mm, sonar0, v0_div, updates, detour_mm, side, v0):
    """method001.py's start_001, update_001 and escape_001 against the board's replanner on
    drawn sequences (the first plan slower by v0_div as a fallback step asks): the same paths,
    decisions, reasons and modelled time, the same detour heading after each update."""
    from mobigrasp.host.task.method001 import start_001, update_001

    # v0 in odd mm/s at a slow-down level and v0_div: the halves round as Python's round
    base = Params001(**{**planner_params_001(TaskParams.for_method("001")).__dict__, "v0": v0})
    params = Params001(**{**base.__dict__, "v0": base.v0 / v0_div})
    rp, fol, ops, detail = start_001(0, 0, 0, 0, 200, target_mm, tuple(sonar0), params)
    b = _board(rp, base.v0)
    traj, o = FFI.new("mg_trajectory_t *"), FFI.new("mg_plan_outcome_t *")
    inp = _inputs(*state_m(0, 0, 0, 200), sonar0)
    C.mg_board_replanner001.start(b, 0, inp, list(target_mm), v0_div, traj, o)
    assert (bool(o.has_path), FFI.string(o.reason).decode(), o.time_us) == (
        fol is not None, detail["reason"], ops.time_us())
    t_us = 0
    for dt_us, (x_mm, y_mm, h_mrad, v_mmps), sonar, force in updates:
        t_us += dt_us
        dec, fol, ops = update_001(rp, t_us, x_mm, y_mm, h_mrad, v_mmps, tuple(sonar), force)
        inp = _inputs(*state_m(x_mm, y_mm, h_mrad, v_mmps), sonar)
        c_dec, c_ops = FFI.new("mg_replan001_t *"), FFI.new("mg_ops_t *")
        C.mg_board_replanner001.update(b, t_us, inp, force, c_dec, traj, o, c_ops)
        assert (c_dec.blocked, c_dec.replanned, c_dec.has_curve, c_dec.has_plan) == (
            dec.blocked, dec.replanned, dec.curve is not None, dec.plan is not None)
        assert FFI.string(o.reason).decode() == dec.reason
        assert hostc.ops_tuple(c_ops[0]) == ops.as_tuple() and bool(o.has_path) == (
            fol is not None)
        event(dec.reason.split(":")[0].split(" ")[0])
        event("escape " + _same_escape(b, rp, inp, target_mm, detour_mm, side))
