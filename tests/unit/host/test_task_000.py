"""Method 000 (host/task/method000.py): what closes the gripper, the long-range experiment 2.

The fast tests run the task in the float world of test_task_closed_loop.py; the slow one runs
the shipped paper000-exp2 over the pty.
"""

import math

import detections as det
import pytest
from test_task_closed_loop import World

from mobigrasp.cosim.run_folder import read_trace
from mobigrasp.host import arm_calib
from mobigrasp.host.app_factory import task_params
from mobigrasp.host.task import Task, TaskInputs
from mobigrasp.host.task.adjust import ADJUST
from mobigrasp.services.run_job import RunOptions, execute, resolve_scenario


def run_details(task, world, t_end_us=120_000_000, period_us=20_000, frame_every=3):
    """Step the task in ``world`` to DONE or FAILED: (events, details, arm) in time order,
    ``arm`` the commanded (t_us, theta2, theta5, wheels) of every step."""
    events, details, arm, t, k = [], [], [], 0, 0
    while t < t_end_us and task.state not in ("DONE", "FAILED"):
        out = task.step(t, world.inputs(task, k % frame_every == 0))
        for ch, a in enumerate(out.servo_mrad):
            assert arm_calib.within_limits(ch, a)
        events.extend(out.events)
        arm.append((t, out.servo_mrad[2], out.servo_mrad[5], tuple(out.wheels_mmps)))
        if out.detail:
            details.append((t, task.state, out.detail))
        world.apply(out, period_us / 1e6)
        t, k = t + period_us, k + 1
    return events, details, arm


class SpokeWorld(World):
    """The spoke is seen on the "+" under the camera (the object's top in the frame, at most
    0.3 m away); it turns in the image against the wrist roll (the host's sign, kinematics
    ``precise_grasp_step``: a positive roll step removes a positive image angle), its angle
    ``SPOKE_MRAD`` at roll 0, 6 mm wide."""

    SPOKE_MRAD = 300

    def detect(self, names):
        out = super().detect(names)
        if "spoke" in names:
            pr = self.project((self.obj[0], self.obj[1], self.top_h))
            out["spoke"] = None if pr is None or pr[2] > 0.3 else det.spoke(
                self.SPOKE_MRAD - self.joints[1], 16 * round(6 * self.f / (pr[2] * 1000)))
        return out


class NoSpokeWorld(World):
    """The spoke detector never finds the spoke (the "+" arms out of its reach)."""

    def detect(self, names):
        out = super().detect(names)
        if "spoke" in out:
            out["spoke"] = None
        return out


@pytest.mark.parametrize("world_cls,condition", [(SpokeWorld, "precise"),
                                                       (NoSpokeWorld, "no_spoke")])
def test_the_trace_says_what_closed_the_gripper(world_cls, condition):
    """The close is logged as ``grasp_close``: "precise" when k_T = 0 and w_T in [w_min, w_max]
    (000 §III.C.2) decided it, the fallback's name when it did not."""
    task = Task("000")
    world = world_cls((0.9, -0.4), pose=(0.0, 0.0, 0.3))
    events, details, arm = run_details(task, world)
    closes = [d["grasp_close"] for _, _, d in details if "grasp_close" in d]
    assert closes == [condition], (task.failure, [(e.to_state, e.why) for e in events])
    if condition == "precise":
        aligned = [d["precise"] for _, _, d in details if "precise" in d][-1]
        assert aligned["reason"].startswith("k_T ~ 0")
        assert task.p.w_min_px <= aligned["w_px"] <= task.p.w_max_px
        assert task.state == "DONE" and world.held


def test_experiment_2_is_long_range():
    """000 experiment 2 is "a long-range move-to-grasp task": the object stands at least 2.5 m
    from the start, beyond the radial symbol's ~1.1 m (the robot must search and wander)."""
    _, sc = resolve_scenario("paper000-exp2")
    dist = math.hypot(sc.target.x_m - sc.robot.x_m, sc.target.y_m - sc.robot.y_m)
    assert dist >= 2.5


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_experiment_2_grasps_over_the_pty_by_the_precise_condition(tmp_path):
    summary, code = execute(RunOptions(scenario="paper000-exp2", transport="pty",
                                       out=tmp_path / "e2", progress=False, plots=False))
    brief = {k: summary.get(k) for k in ("end_reason", "task_state", "final_error_mm")}
    assert code == 0 and summary["success"] and summary["grasped"], brief
    assert not summary["false_claim"] and summary["safety"]["contacts"] == 0, brief
    trace = read_trace(tmp_path / "e2" / "trace.jsonl")
    assert [e["grasp_close"] for e in trace if "grasp_close" in e] == ["precise"]
    # the object was out of sight from the start: found after the robot wandered toward it
    found = next(e for e in trace if e.get("ev") == "state" and e["to"] == "APPROACH")
    assert any("wander_mm" in e for e in trace if e["t_us"] < found["t_us"])


class BlackoutWorld(SpokeWorld):
    """The camera sees nothing for ``dark_us`` from the first frame of ADJUST on (the object
    lost during the adjustment), then sees again."""

    def __init__(self, *a, dark_us=6_000_000, **kw):
        super().__init__(*a, **kw)
        self.dark_us, self.dark_from, self.t_us = dark_us, None, 0

    def inputs(self, task, frame):
        if task.state == "ADJUST" and self.dark_from is None:
            self.dark_from = self.t_us
        self.t_us += 20_000
        return super().inputs(task, frame)

    def detect(self, names):
        out = super().detect(names)
        if self.dark_from is not None and self.t_us - self.dark_from < self.dark_us:
            return {n: None for n in names}
        return out


@pytest.mark.parametrize("dtheta2_l", [0.06, 0.1])
def test_lost_during_adjustment_searches_by_fig5_with_d_theta2_and_finds_it_again(dtheta2_l):
    """000 §III.B.2: lost in ADJUST, the platform stops and the arm searches by Fig. 5: theta2
    in steps of d_theta2 (the scenario's dtheta2_l, 0.06 rad), theta5 from end to end at each
    theta2; the object is found again and grasped. The path ends 0.7 m short of the object, so
    that the loss happens too far from it to finish the adjustment on odometry."""
    step = round(dtheta2_l * 1000)
    params = task_params("000", {"dtheta2_l": dtheta2_l})  # the scenario's [params] key
    task = Task("000", {**params, "approach_standoff_mm": 700})
    world = BlackoutWorld((0.9, -0.4), pose=(0.0, 0.0, 0.3))
    events, details, arm = run_details(task, world)
    path = [(e.from_state, e.to_state) for e in events]
    assert ("ADJUST", "LOST") in path and ("LOST", "SEARCH") in path, path
    t_search = next(e.t_us for e in events if e.to_state == "SEARCH")
    t_found = next(e.t_us for e in events if e.from_state == "SEARCH" and e.t_us > t_search)
    lost = [d["lost_search"] for _, _, d in details if "lost_search" in d]
    assert len(lost) == 1 and lost[0]["lost_in"] == "ADJUST"
    assert lost[0]["d_theta2_mrad"] == step
    assert task.state == "DONE" and world.held, (task.failure, path)
    # the search's commanded (theta2, theta5) between LOST and the re-acquisition
    poses = []
    for t_us, th2, th5, _ in arm:
        if t_search < t_us < t_found and (not poses or poses[-1] != (th2, th5)):
            poses.append((th2, th5))
    levels = [p[0] for k, p in enumerate(poses) if k == 0 or poses[k - 1][0] != p[0]]
    assert len(levels) >= 2, poses
    # Fig. 5 from theta2s: up in d_theta2 steps to theta2_max, then below theta2s down to
    # theta2_min (host/search.py)
    assert all(abs(b - a) == step or b in (-2100, -2800, levels[0] - step)
               for a, b in zip(levels, levels[1:], strict=False)), levels
    for lv in levels[1:-1]:  # a whole sweep of theta5 at each theta2 passed over
        sweep = [th5 for th2, th5 in poses if th2 == lv]
        assert {sweep[0], sweep[-1]} == {-800, 800}, (lv, sweep)


class PushedWorld(SpokeWorld):
    """The object is pushed ``push_m`` farther along the robot's heading when the precise grasp
    begins: it is no longer under the camera (lost during the grasp)."""

    def __init__(self, *a, push_m=0.1, **kw):
        super().__init__(*a, **kw)
        self.push_m, self.pushed = push_m, False

    def inputs(self, task, frame):
        if task.state == "PRECISE_GRASP" and not self.pushed:
            self.pushed = True
            self.obj = (self.obj[0] + self.push_m * math.cos(self.h),
                        self.obj[1] + self.push_m * math.sin(self.h))
        return super().inputs(task, frame)


def test_lost_during_the_grasp_searches_by_fig5_and_grasps_it_where_it_is_now():
    """000 §III.C: "the object searching when lost is similar to ... Fig. 5". No spoke under
    the camera at the hover (the object was pushed away): the platform stays, the arm searches
    by Fig. 5 from theta2_min in d_theta2 steps, finds the object, and the task approaches and
    grasps it there by the precise condition (not by going down on the rough position)."""
    task = Task("000")
    world = PushedWorld((0.9, -0.4), pose=(0.0, 0.0, 0.3))
    events, details, arm = run_details(task, world)
    path = [(e.from_state, e.to_state) for e in events]
    assert ("PRECISE_GRASP", "LOST") in path, path
    t_search = next(e.t_us for e in events if e.from_state == "LOST")
    t_found = next(e.t_us for e in events if e.from_state == "SEARCH" and e.t_us > t_search)
    lost = [d["lost_search"] for _, _, d in details if "lost_search" in d]
    assert lost == [{"lost_in": "PRECISE_GRASP", "theta2s_mrad": -2800,
                     "theta5s_mrad": lost[0]["theta5s_mrad"], "d_theta2_mrad": 60}], lost
    # the base stood still from the loss to the re-acquisition
    assert all(w == (0, 0) for t_us, _, _, w in arm if t_search < t_us < t_found)
    assert task.state == "DONE" and world.held, (task.failure, path)
    assert [d["grasp_close"] for _, _, d in details if "grasp_close" in d] == ["precise"]


def test_the_searches_after_a_loss_are_000s_only():
    """001 derives from 000's hooks but keeps the usual search and the rough-position fallback."""
    from mobigrasp.host.search import SearchParams

    task = Task("001")
    assert task.rules.lost_search(task, SearchParams(), "ADJUST") is None
    assert task.rules.grasp_lost(task, 0, 3_000_000) is False and task.state == "SEARCH"
    t000 = Task("000")
    t000.state = "PRECISE_GRASP"
    assert t000.rules.grasp_lost(t000, 0, 3_000_000) and t000.state == "LOST"
    assert not t000.rules.grasp_lost(t000, 1, 3_000_000)  # once per run


SEARCH_POSTURE = (-2650, -200, 2300, 100)  # the search's theta2..theta5 (host/search.py)


def _adjust_steps(task, steps=10, period_us=20_000) -> list:
    """Enter ADJUST in the search posture, the object 300 mm ahead and 40 mm right of the
    waist, and step it without detections (not long enough to be lost): the arm after each."""
    task.arm[2:6] = list(SEARCH_POSTURE)
    task.obj = (400, -40)  # odometry frame; the platform at the origin facing +x
    task.go(0, "ADJUST", "test")
    inp = TaskInputs()
    ADJUST.enter_ADJUST(task, 0, inp)
    arms = [list(task.arm)]
    for k in range(1, steps + 1):
        ADJUST.do_ADJUST(task, k * period_us, inp, {})
        arms.append(list(task.arm))
    assert task.state == "ADJUST"
    return arms


def test_adjust_starts_from_the_posture_it_enters_with_and_moves_by_eq_10():
    """000's ADJUST makes no jump on entry: with 000 §IV's gains (k_theta2 = 1, k_theta3 =
    k_theta4 = 0) theta3 and theta4 stay where the search left them while theta2 pitches the
    camera to the object and theta5 turns to it (eq. (10)); with non-zero k_theta3, k_theta4
    those joints move too."""
    arms = _adjust_steps(Task("000"))
    assert arms[0][2:6] == list(SEARCH_POSTURE)  # the entry commands nothing
    assert all(a[3:5] == [-200, 2300] for a in arms)
    assert arms[-1][2] != SEARCH_POSTURE[0] and arms[-1][5] != SEARCH_POSTURE[3]
    gains = Task("000", {"posture": {"k_theta_q12": (4096, 4096, 4096)}})
    moved = _adjust_steps(gains)
    assert moved[0][2:6] == list(SEARCH_POSTURE)
    assert moved[-1][3] != -200 and moved[-1][4] != 2300
    # eq. (10) shares the pitch change among the joints: the camera pitches the same way
    alpha0 = sum(SEARCH_POSTURE[:3])
    assert (sum(moved[-1][2:5]) - alpha0) * (sum(arms[-1][2:5]) - alpha0) > 0


def test_001_adjust_still_enters_the_close_look_posture():
    """001 (its long arm looks from the close-look posture) keeps the entry posture of
    ``adjust_theta3_mrad``, ``adjust_theta4_mrad``, the camera pitch kept."""
    task = Task("001")
    arms = _adjust_steps(task, steps=0)
    assert arms[0][3:5] == [task.p.adjust_theta3_mrad, task.p.adjust_theta4_mrad]
    assert sum(arms[0][2:5]) == sum(SEARCH_POSTURE[:3])
