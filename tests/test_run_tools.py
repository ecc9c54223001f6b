"""Campaign scenarios, the profile table, scenario resolution."""

import math

import pytest

from mobigrasp.tools.commands.profile import profile_table
from mobigrasp.tools.random_scenarios import random_scenario
from mobigrasp.tools.run_job import BadInput, parse_speed, resolve_scenario


@pytest.mark.parametrize("method", ["000", "001", "002"])
def test_random_scenarios_follow_the_campaign_rules(method):
    dists = []
    for seed in range(25):
        sc = random_scenario(method, seed)
        assert sc.meta.method == method and sc.meta.seed == seed
        d = math.hypot(sc.target.x_m - sc.robot.x_m, sc.target.y_m - sc.robot.y_m)
        assert 0.5 <= d <= 3.0
        dists.append(d)
        for o in sc.obstacles:  # never on top of the start or the target
            assert math.hypot(o.x_m, o.y_m) > 0.3
            assert math.hypot(o.x_m - sc.target.x_m, o.y_m - sc.target.y_m) > 0.3
        if method == "002":
            assert len(sc.target.path) == 2
        else:
            assert not sc.target.path
    assert max(dists) - min(dists) > 1.5  # spread over the range
    assert random_scenario(method, 3) == random_scenario(method, 3)  # seeded
    if method == "001":
        assert sum(len(random_scenario("001", s).obstacles) for s in range(25)) > 12


def test_profile_names_the_stage_closest_to_its_budget():
    stages = {
        "control": {"calls": 10, "mean_us": 150.0, "p95_us": 200, "max_us": 19_000,
                    "total_us": 1500},
        "radial_symbol": {"calls": 5, "mean_us": 20_000.0, "p95_us": 30_000, "max_us": 40_000,
                          "total_us": 100_000},
    }
    rows, first = profile_table(stages, {"radial_symbol": [0.004, 0.006], "task": [0.001]})
    assert first == "control"  # 19 ms of a 20 ms period beats 40 ms of a 66.7 ms frame
    by = {r["stage"]: r for r in rows}
    assert by["radial_symbol"]["wall_mean_ms"] == pytest.approx(5.0)
    assert by["radial_symbol"]["share_max"] == pytest.approx(0.6, abs=0.001)
    assert "task (python)" in by


def test_resolve_scenario_and_speed():
    path, sc = resolve_scenario("paper000-exp1")
    assert path.name == "paper000-exp1.toml" and sc.meta.method == "000"
    with pytest.raises(BadInput, match="paper000-exp1"):  # the message lists what exists
        resolve_scenario("nope")
    assert parse_speed("max") is None and parse_speed("2.5") == 2.5
    for bad in ("0", "-1", "nan", "inf", "x"):
        with pytest.raises(BadInput):
            parse_speed(bad)
