"""Scenario TOML: example files load; bad files give errors naming file, key and expectation."""

import math
from pathlib import Path

import pytest

from mobigrasp.host.task import REGISTRY
from mobigrasp.mcu_sim.world.scenario import (
    ScenarioError,
    load_scenario,
    loads_scenario,
)

DATA = Path(__file__).resolve().parents[2] / "data" / "scenarios"

GOOD = """
[scenario]
name = "t"
method = "001"
seed = 4
time_limit_s = 30.0

[robot]
x_m = 0.5
y_m = -1
heading_rad = 0.25

[target]
kind = "red-cylinder"
x_m = 2.0
y_m = 1.0
heading_rad = 0.0

[[obstacles]]
shape = "circle"
x_m = 1.0
y_m = 0.0
radius_m = 0.2

[params]
k_s = 4
Vmax = 0.3
"""


@pytest.mark.parametrize("path", sorted(DATA.glob("*.toml")), ids=lambda p: p.name)
def test_example_files_load(path):
    s = load_scenario(path, methods=REGISTRY)
    assert s.meta.method in ("000", "001", "002")
    assert set(s.params) == set(REGISTRY[s.meta.method].paper_params)
    assert s.source == str(path)


def test_values_and_defaults():
    s = loads_scenario(GOOD, "good.toml", methods=REGISTRY)
    assert s.meta.seed == 4 and s.meta.time_limit_s == 30.0
    assert (s.robot.x_m, s.robot.y_m, s.robot.heading_rad) == (0.5, -1.0, 0.25)
    assert s.obstacles[0].radius_m == 0.2 and s.obstacles[0].height_m == 0.3
    assert s.params["k_s"] == 4 and s.params["Vmax"] == 0.3
    assert s.params["A_g"] == 1.05 and s.params["D_e"] == 2.5  # 001 paper defaults
    assert dict(s.param_overrides) == {"k_s": 4, "Vmax": 0.3}
    assert s.camera.f_px == 611.0 and s.camera.noise_std == 0.0
    assert loads_scenario(GOOD.replace('"001"', '"002"').replace("k_s = 4\nVmax = 0.3", ""),
                          "x", methods=REGISTRY).camera.f_px == 350.0
    with pytest.raises(TypeError):
        s.params["k_s"] = 3  # read-only
    p = load_scenario(DATA / "method_002.toml", methods=REGISTRY).target.path
    assert [(q.t_s, q.x_m, q.y_m) for q in p] == [(5.0, 0.5, 2.0), (20.0, 1.0, 2.4)]


def bad(text, *fragments):
    with pytest.raises(ScenarioError) as e:
        loads_scenario(text, "bad.toml", methods=REGISTRY)
    msg = str(e.value)
    assert msg.startswith("bad.toml: ")
    for f in fragments:
        assert f in msg, msg
    return msg


def test_unknown_keys_are_errors():
    bad(GOOD.replace("seed = 4", "seed = 4\ncolour = 3"), "scenario.colour", "unknown key")
    bad(GOOD + "\n[extra]\na = 1\n", "bad.toml: extra: unknown key")
    bad(GOOD.replace("radius_m = 0.2", "radius_m = 0.2\nwidth_m = 1.0"), "obstacles[0].width_m")
    bad(GOOD.replace("Vmax = 0.3", "vmax_mps = 0.3"), "params.vmax_mps",
        "a parameter of method 001")


def test_wrong_types_are_errors():
    bad(GOOD.replace("x_m = 0.5", 'x_m = "0.5"'), "robot.x_m", "expected a number", "'0.5'")
    bad(GOOD.replace("seed = 4", "seed = 4.5"), "scenario.seed", "an integer")
    bad(GOOD.replace("seed = 4", "seed = true"), "scenario.seed", "an integer")
    bad(GOOD.replace('method = "001"', "method = 1"), "scenario.method", '"000"')
    bad(GOOD.replace('kind = "red-cylinder"', 'kind = "blue-cube"'), "target.kind", "blue-cube")
    bad(GOOD.replace("k_s = 4", "k_s = 4.5"), "params.k_s", "an integer")
    bad(GOOD.replace('shape = "circle"', 'shape = "blob"'), "obstacles[0].shape")
    robot = "[robot]\nx_m = 0.5\ny_m = -1\nheading_rad = 0.25\n"
    assert robot in GOOD
    bad("robot = 3\n" + GOOD.replace(robot, ""), "bad.toml: robot: expected a table")


def test_missing_fields_are_errors():
    bad(GOOD.replace("time_limit_s = 30.0", ""), "scenario.time_limit_s", "missing")
    bad(GOOD.replace("radius_m = 0.2", ""), "obstacles[0].radius_m", "missing")
    target = '[target]\nkind = "red-cylinder"\nx_m = 2.0\ny_m = 1.0\nheading_rad = 0.0\n'
    assert target in GOOD
    bad(GOOD.replace(target, ""), "bad.toml: target: expected a table")
    bad(GOOD.replace('name = "t"', ""), "scenario.name", "a non-empty string")


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_nan_and_inf_are_rejected(value):
    bad(GOOD.replace("y_m = -1", f"y_m = {value}"), "robot.y_m", "a finite number")
    bad(GOOD.replace("Vmax = 0.3", f"Vmax = {value}"), "params.Vmax", "a finite number")


def test_range_checks():
    bad(GOOD.replace("time_limit_s = 30.0", "time_limit_s = 0"), "time_limit_s",
        "in [0.001, 3600] s")
    bad(GOOD.replace("radius_m = 0.2", "radius_m = -0.2"), "radius_m", "in [0.005, 10] m")
    bad(GOOD.replace("seed = 4", "seed = -1"), "scenario.seed",
        "in [0, 18446744073709551615]")
    path = """
[[target.path]]
t_s = 2.0
x_m = 0
y_m = 0
[[target.path]]
t_s = 1.0
x_m = 0
y_m = 0
"""
    bad(GOOD.replace("[[obstacles]]", path + "\n[[obstacles]]"), "target.path[1].t_s",
        "strictly increasing")


def test_faults_must_be_a_table_of_known_keys():
    # the [faults] schema itself is tested in tests/unit/mcu_sim/test_faults_plan.py
    s = loads_scenario(GOOD + "\n[faults]\nmotor_fail = {wheel = \"left\", at_s = 3.0}\n", "f",
                       methods=REGISTRY)
    assert s.faults.motor_fail.wheel == "left" and s.faults.motor_fail.at_s == 3.0
    bad("faults = 3\n" + GOOD, "bad.toml: faults: expected a table", "3")
    bad(GOOD + "\n[faults]\nmotor_stuck = 1\n", "bad.toml: faults.motor_stuck: unknown key")


def test_file_errors_name_the_file(tmp_path):
    with pytest.raises(ScenarioError, match="missing.toml"):
        load_scenario(tmp_path / "missing.toml", methods=REGISTRY)
    p = tmp_path / "broken.toml"
    p.write_text("[scenario\nname=")
    with pytest.raises(ScenarioError, match="broken.toml: not valid TOML"):
        load_scenario(p, methods=REGISTRY)
    assert math.isfinite(load_scenario(DATA / "method_000.toml", methods=REGISTRY).params["rmin_m"])


def test_docs_list_every_parameter_range():
    """docs/conventions.md "Scenario value ranges" lists each paper parameter as the loader
    checks it (method, key, paper value, range, unit)."""
    from mobigrasp.mcu_sim.world.scenario import CAMERA_RANGES, OBSTACLE_RANGES

    doc = (Path(__file__).resolve().parents[3] / "docs" / "conventions.md").read_text()

    def num(v, kind=float):
        return f"{int(v)}" if kind is int else f"{v:g}"
    for method, rules in REGISTRY.items():
        for key, p in rules.paper_params.items():
            row = (f"| {method} | `{key}` | {num(p.default, p.kind)} | "
                   f"[{num(p.lo, p.kind)}, {num(p.hi, p.kind)}] | {p.unit} |")
            assert row in doc, row
    for key, (lo, hi) in CAMERA_RANGES.items():
        assert f"| `camera.{key}` | [{lo:g}, {hi:g}] |" in doc, key
    for key, (lo, hi) in OBSTACLE_RANGES.items():
        assert f"| `obstacles[].{key}` | [{lo:g}, {hi:g}] | m |" in doc, key


@pytest.mark.parametrize(("method", "key", "value"), [
    ("000", "k_s", 5), ("000", "alpha_T", -1.5), ("001", "h_e", 0.2), ("002", "n", 10),
    ("002", "T_h", 30), ("002", "D", 0.0145)])
def test_a_paper_parameter_nothing_reads_is_refused_by_name(method, key, value):
    text = GOOD.replace('"001"', f'"{method}"').replace("k_s = 4\nVmax = 0.3", f"{key} = {value}")
    with pytest.raises(ScenarioError, match=f"params.{key}: {key} is not used by method {method}"):
        loads_scenario(text, "x.toml", methods=REGISTRY)


def test_the_remaining_000_parameters_reach_the_task():
    from mobigrasp.host.app_factory import task_params
    from mobigrasp.host.task import Task

    p = Task("000", params=task_params("000", {"k_theta2": 0.5, "k_theta3": 0.25,
                                                "w_min": 15, "w_max": 50})).p
    assert p.posture["k_theta_q12"] == (2048, 1024, 0)
    assert (p.w_min_px, p.w_max_px) == (15, 50)
    assert Task("000").posture_params().k_theta_q12 == (4096, 0, 0)
    assert Task("000", params=task_params("000", {"k_theta2": 0.5})).posture_params(
    ).k_theta_q12 == (2048, 0, 0)
