"""The per-method interface of the task (host/task/method.py): one object per method, chosen by
name, and the machine asks it wherever the methods differ."""

import inspect
from pathlib import Path

import pytest

from mobigrasp.host.task import METHODS, Method, Task, TaskInputs, TaskParams, method_rules
from mobigrasp.host.vision import registry

HOST = Path(__file__).resolve().parents[3] / "host"


@pytest.mark.parametrize("name", sorted(METHODS))
def test_each_method_implements_the_interface_and_names_registered_detectors(name):
    rules = method_rules(name)
    assert isinstance(rules, Method) and rules.name == name and rules is method_rules(name)
    assert not inspect.isabstract(type(rules))
    names = {rules.search_detector, rules.adjust_detector, *rules.check_detectors}
    for used in rules.detectors.values():
        names |= set(used)
    assert all(registry.row(n) for n in names)
    assert rules.search_detector in rules.detectors["SEARCH"]
    task = Task(name)
    assert task.rules is rules and task.cam == rules.camera
    for key, value in rules.param_defaults.items():
        assert getattr(task.p, key) == value or key == "search"
    assert task.detectors_needed() == list(rules.detectors["SEARCH"])


def test_unknown_method_is_refused_by_name():
    with pytest.raises(ValueError, match="003"):
        method_rules("003")
    with pytest.raises(ValueError, match="method"):
        TaskParams.for_method("003")


def test_the_machine_asks_the_method_object():
    # a method object with another search detector: the machine looks for what it says
    base = method_rules("000")

    class Other(type(base)):
        search_detector = "double_cross"
        detectors = {**base.detectors, "SEARCH": ("double_cross",)}

    task = Task("000")
    task.rules = Other()
    out = task.step(0, TaskInputs(detections={"radial_symbol": object()}))
    assert task.counters["bad_detections"] == 0  # the radial symbol is not looked at
    assert out.state == "SEARCH" and task.detectors_needed() == ["double_cross"]


def test_no_method_string_comparisons_in_the_host():
    for path in HOST.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        assert "method ==" not in text and "method !=" not in text, path


def _guarded(sonar_mm, obj_xy_mm, wheels=(200, 200), state="APPROACH"):
    from mobigrasp.host.task import Task, TaskInputs

    task = Task("001")
    task.state, task.wheels, task.obj = state, wheels, obj_xy_mm
    task.follower = "a path"
    task.rules.guard_wheels(task, 0, TaskInputs(sonar_mm=sonar_mm))
    return task


def test_sonar_below_safety_circle_stops_forward_motion_and_drops_the_path():
    far = (3000, 0)
    stopped = _guarded((2500, 2500, 150, 2500, 2500), far)
    assert stopped.wheels == (0, 0) and stopped.follower is None
    diag = _guarded((2500, 190, 2500, 2500, 2500), far)  # S_2 at -pi/4
    assert diag.wheels == (0, 0)
    for kept in (_guarded((2500, 2500, 250, 2500, 2500), far),  # beyond R_r = 200 mm
                 _guarded((150, 2500, 2500, 2500, 150), far),  # the side sonars (phi = +-pi/2)
                 _guarded((2500, 2500, 150, 2500, 2500), far, wheels=(-80, 80)),  # turn
                 _guarded((2500, 2500, 0, 2500, 2500), far),  # 0: no echo
                 _guarded((2500, 2500, 150, 2500, 2500), far, state="ADJUST")):
        assert kept.wheels != (0, 0) and kept.follower == "a path"


def test_sonar_guard_in_approach_turns_toward_the_widest_free_sector_first():
    # an echo below R_r ahead and on the right, the left free: turn left in place, then leave
    # R_r along that sector before the next plan
    from mobigrasp.host.task.sonar_guard import GUARD_OUT_MM

    task = _guarded((300, 150, 150, 2500, 2500), (3000, 0))
    assert task.wheels == (0, 0) and task.ms.detour["drive"] is True
    assert task.ms.detour["length_mm"] == GUARD_OUT_MM
    assert task.ms.detour["heading_mrad"] > 500  # toward S_4 / S_5 (left, counter-clockwise)
    assert _guarded((300, 150, 150, 2500, 2500), (3000, 0), state="SEARCH").ms.detour is None


def test_sonar_guard_ignores_the_objects_own_echo():
    # sensor S_3 170 mm ahead of the centre, the object estimate 230 mm ahead of it
    assert _guarded((2500, 2500, 150, 2500, 2500), (400, 0)).wheels == (200, 200)
    # the same echo with the object elsewhere is an obstacle
    assert _guarded((2500, 2500, 150, 2500, 2500), (400, 900)).wheels == (0, 0)


def test_r_r_and_sonar_cone_come_from_the_scenario():
    from mobigrasp.host.app_factory import task_params
    from mobigrasp.host.task import Task
    from mobigrasp.host.task.method001 import planner_params_001

    task = Task("001", params=task_params("001", {"R_r": 0.3, "A_g": 0.9, "D_e": 2.0}))
    assert task.p.r_r_mm == 300
    sonar = planner_params_001(task.p).sonar
    assert (sonar.r_r_m, sonar.a_g_rad, sonar.d_e_m) == (0.3, 0.9, 2.0)
    assert _guarded((2500, 2500, 250, 2500, 2500), (3000, 0)).wheels == (200, 200)
    wide = Task("001", params={"r_r_mm": 300})
    wide.state, wide.wheels, wide.obj = "APPROACH", (200, 200), (3000, 0)
    from mobigrasp.host.task import TaskInputs
    wide.rules.guard_wheels(wide, 0, TaskInputs(sonar_mm=(2500, 2500, 250, 2500, 2500)))
    assert wide.wheels == (0, 0)


def test_001_falls_back_in_steps_before_giving_up():
    """No feasible curve: lower v0, back off toward the last path's start, turn toward the
    widest free sector, then drives aside (max_detours), each a fallback detail event; then
    no more (the caller ends FAILED)."""
    from mobigrasp.host.task import Task, TaskInputs
    from mobigrasp.host.task.method001 import start_001

    task = Task("001", params={"max_detours": 2})
    task.state, task.obj = "APPROACH", (2000, 0)
    # a wall of echoes ahead and right, free to the left (S_4, S_5)
    inp = TaskInputs(x_mm=0, y_mm=0, heading_mrad=0,
                     sonar_mm=(300, 300, 300, 2500, 2500))
    task.ms.replanner = start_001(0, 0, 0, 0, 0, task.obj, inp.sonar_mm)[0]
    task.ms.path_from = (-600, 0)
    steps = []
    for _ in range(6):
        task._detail = {}
        ok = task.rules.start_detour(task, inp)
        steps.append((task._detail.get("fallback", {}).get("step"), ok))
        if steps[-1][0] == "lower_v0":
            assert task.ms.v0_div == 2 and task.ms.replanner is None
            task.ms.replanner = start_001(0, 0, 0, 0, 0, task.obj, inp.sonar_mm)[0]
        elif steps[-1][0] == "back_off":
            assert task.ms.detour["drive"] and abs(abs(task.ms.detour["heading_mrad"]) - 3142) <= 2
        elif steps[-1][0] == "widest_sector":
            assert not task.ms.detour["drive"] and 785 <= task.ms.detour["heading_mrad"] <= 1571
    assert steps == [("lower_v0", True), ("back_off", True), ("widest_sector", True),
                     ("detour", True), ("detour", True), (None, False)]


def test_lower_v0_reaches_the_planner():
    from mobigrasp.host.task import Task, TaskInputs

    task = Task("001")
    task.obj, task.ms.v0_div = (2000, 300), 2
    follower, _, detail = task.rules.plan(task, 0, TaskInputs(sonar_mm=(2500,) * 5))
    assert task.ms.replanner.params.v0 == 0.1 and follower is not None
    assert task.ms.path_from == (0, 0)


def test_001_looks_at_a_near_given_object_before_the_first_plan():
    """P_i given 0.6 m off to the left and never seen: before the first plan the base turns
    in place toward it with the camera in the search's look; once seen (or far), it plans."""
    from mobigrasp.host.search import SearchParams
    from mobigrasp.host.task import Task, TaskInputs

    task = Task("001", params={"object_xy_mm": (100, 600)})
    task.state, task.entered_us, task.obj = "APPROACH", 0, (100, 600)
    inp = TaskInputs(x_mm=0, y_mm=0, heading_mrad=0, sonar_mm=(2500,) * 5)
    assert task.rules.hold_before_plan(task, 100_000, inp)
    assert task.wheels[1] > 0 > task.wheels[0]  # counter-clockwise, toward the left
    sp = SearchParams(**task.p.search)
    assert task.arm[2:5] == [sp.coarse_theta2_mrad[0], sp.theta3_mrad, sp.theta4_mrad]
    assert task.arm[5] < 0  # the waist turned toward it (left of the heading)
    task.object_sighted = True
    task.rules.hold_before_plan(task, 300_000, inp)
    assert task.rules.look_first(task, 300_000, inp) is False
    far = Task("001", params={"object_xy_mm": (3000, 0)})
    far.state, far.entered_us, far.obj = "APPROACH", 0, (3000, 0)
    assert far.rules.look_first(far, 100_000, inp) is False


@pytest.mark.parametrize("method", ["000", "002"])
@pytest.mark.parametrize("state", ["SEARCH", "APPROACH"])
def test_000_and_002_are_guarded_too_stop_turn_and_drive_out_of_r_r(method, state):
    """The sonar guard of 000 and 002 (host/task/sonar_guard.py): a front echo below R_r stops
    the forward drive and drops the path; the base then turns toward the widest free sector
    and drives GUARD_OUT_MM along it, whatever the state asks meanwhile, then the state goes
    on; the object's own echo and echoes beyond R_r stop nothing."""
    from mobigrasp.host.task import Task, TaskInputs
    from mobigrasp.host.task.sonar_guard import GUARD_OUT_MM

    task = Task(method)
    task.state, task.wheels, task.obj, task.follower = state, (200, 200), (3000, 0), "a path"
    echo = (300, 150, 150, 2500, 2500)  # ahead and on the right; the left free
    task.rules.guard_wheels(task, 0, TaskInputs(sonar_mm=echo))
    assert task.wheels == (0, 0) and task.follower is None
    assert task.guard_out["heading_mrad"] > 500 and task.guard_out["length_mm"] == GUARD_OUT_MM
    task.wheels = (200, 200)  # the state drives on: the guard turns the base instead
    task.rules.guard_wheels(task, 20_000, TaskInputs(sonar_mm=echo))
    assert task.wheels[0] < 0 < task.wheels[1]  # counter-clockwise, in place
    heading = task.guard_out["heading_mrad"]
    free = (2500,) * 5
    task.rules.guard_wheels(task, 40_000, TaskInputs(heading_mrad=heading, sonar_mm=free))
    assert task.wheels[0] == task.wheels[1] > 0  # out along the free sector
    task.rules.guard_wheels(task, 60_000, TaskInputs(
        heading_mrad=heading, x_mm=0, y_mm=GUARD_OUT_MM, sonar_mm=free))
    assert task.guard_out is None and task.wheels == (0, 0)
    task.wheels = (200, 200)  # released: the state's wheels stand
    task.rules.guard_wheels(task, 80_000, TaskInputs(sonar_mm=free))
    assert task.wheels == (200, 200)
    for kept, obj in (((2500, 2500, 250, 2500, 2500), (3000, 0)),  # beyond R_r
                      ((2500, 2500, 150, 2500, 2500), (400, 0))):  # the object's own echo
        task.obj, task.wheels = obj, (200, 200)
        task.rules.guard_wheels(task, 100_000, TaskInputs(sonar_mm=kept))
        assert task.wheels == (200, 200) and task.guard_out is None
