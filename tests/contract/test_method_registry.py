"""Adding a method is its own module plus one row of the registry (docs/architecture.md,
"Adding a method"): a toy method (tests/toy_method.py) registered from the test is accepted by
the scenario loader, the CLI, campaigns and the scene generator, and the host runs it."""

import pytest

from mobigrasp.host.task import METHODS, REGISTRY, Task, TaskInputs, method_rules
from mobigrasp.mcu_sim.world.scenario import ScenarioError, loads_scenario

TOY_SCENARIO = """
[scenario]
name = "toy-creep"
method = "toy"
seed = 3
time_limit_s = 1.0

[robot]
x_m = 0.0
y_m = 0.0
heading_rad = 0.0

[target]
kind = "radial-symbol"
x_m = 2.0
y_m = 0.0
heading_rad = 0.0

[params]
creep_mps = 0.2
"""


@pytest.fixture
def toy(monkeypatch):
    monkeypatch.setitem(METHODS, "toy", "toy_method")
    return method_rules("toy")


def test_without_its_row_the_toy_is_unknown_everywhere():
    assert "toy" not in REGISTRY
    with pytest.raises(ScenarioError, match='scenario.method: expected one of "000", "001", '
                                            '"002", got \'toy\''):
        loads_scenario(TOY_SCENARIO, "toy.toml", methods=REGISTRY)
    with pytest.raises(ValueError, match="method must be one of"):
        Task("toy")


def test_a_scenario_naming_the_toy_loads_with_its_parameters_camera_and_robot(toy):
    sc = loads_scenario(TOY_SCENARIO, "toy.toml", methods=REGISTRY)
    assert sc.meta.method == "toy" and sc.meta.robot == "000"
    assert dict(sc.params) == {"creep_mps": 0.2, "shade": 3}  # the file's, then the paper's
    assert (sc.camera.f_px, sc.camera.u0_px, sc.camera.v0_px) == (500.0, 160.0, 120.0)
    with pytest.raises(ScenarioError, match=r"params.creep_mps: expected a number in \[0, 0.3\]"):
        loads_scenario(TOY_SCENARIO.replace("0.2", "0.5"), "toy.toml", methods=REGISTRY)
    with pytest.raises(ScenarioError, match="params.shade: shade is not used by method toy"):
        loads_scenario(TOY_SCENARIO + "shade = 4\n", "toy.toml", methods=REGISTRY)
    with pytest.raises(ScenarioError, match="params.Vmax: unknown key; expected a parameter of "
                                            "method toy: creep_mps, shade"):
        loads_scenario(TOY_SCENARIO + "Vmax = 0.3\n", "toy.toml", methods=REGISTRY)


def test_the_host_runs_the_toy_with_its_parameter_and_its_own_state(toy):
    from mobigrasp.host.app_factory import task_params

    task = Task("toy", params=task_params("toy", {"creep_mps": 0.2}))
    assert type(task.ms).__name__ == "ToyState" and task.ms.steps == 0
    for k in range(5):
        out = task.step(k * 20_000, TaskInputs(joints_mrad=(0, 0, -1571, -1571, 1571, 0)))
        assert out.wheels_mmps == (200, 200) and out.state == "SEARCH"
    assert task.ms.steps == 5 and task.ms.last_mmps == 200
    assert task.detectors_needed() == []
    assert Task("000").ms is not Task("000").ms  # each task a fresh state of its own


def test_the_generator_campaigns_and_the_cli_take_the_toy(toy, capsys):
    from mobigrasp.services.campaign import CampaignConfig, make_scenario
    from mobigrasp.services.random_scenarios import random_scenario
    from mobigrasp.tools.cli import main

    sc = random_scenario("toy", 5, "v2")  # v2 keeps to the scene's hints
    assert sc.meta.method == "toy" and sc.meta.time_limit_s == 60.0
    assert sc.target.kind == "radial-symbol" and not sc.obstacles and not sc.target.path
    sc = random_scenario("toy", 5)  # v3, the default: 180 s and obstacles for every method
    assert sc.meta.method == "toy" and sc.target.kind == "radial-symbol"
    assert sc.meta.time_limit_s == 180.0 and not sc.target.path
    CampaignConfig("toy", 1)  # accepted
    assert make_scenario("toy", 5, CampaignConfig("toy", 1).faults).meta.method == "toy"
    with pytest.raises(SystemExit) as exit_:
        main(["campaign", "--method", "toy", "--runs", "1", "--help"])
    assert exit_.value.code == 0
    with pytest.raises(SystemExit) as exit_:
        main(["campaign", "--method", "tov"])
    assert exit_.value.code == 2
    assert "invalid choice: 'tov' (choose from '000', '001', '002', 'toy')" in \
        capsys.readouterr().err


def test_the_closed_loop_runs_the_toy_on_its_robot(toy, tmp_path):
    from mobigrasp.services.run_job import RunOptions, execute

    path = tmp_path / "toy.toml"
    path.write_text(TOY_SCENARIO, encoding="utf-8")
    summary, _ = execute(RunOptions(scenario=str(path), transport="inproc", out=tmp_path / "run",
                                    plots=False, mcap=False))
    assert summary["status"] == "finished" and summary["method"] == "toy"
    assert summary["task_state"] == "SEARCH" and summary["sim_time_s"] == pytest.approx(1.0)
    # the toy's rule drove the base: ~0.2 m/s for 1 s, less the wheels' start-up
    assert 0.1 < summary["path_length_m"] <= 0.2
