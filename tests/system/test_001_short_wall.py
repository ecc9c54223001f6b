"""001 meets a short wall (0.36 m x 0.05 m) standing at an angle between its start and the
object, close enough that the front sonar reads below R_r: the guard stops the base and turns
it toward free space, the base goes past the wall, and there is no contact (in process, the run
cut once the base is past the wall; docs/task.md "No contact")."""

from __future__ import annotations

import json
import math

import pytest

from mobigrasp.services.run_job import RunOptions, execute

TARGET_XY_M = (-1.7009, 0.6377)
SCENE = f"""[scenario]
name = "short-wall"
method = "001"
seed = 10
time_limit_s = 46.0

[robot]
x_m = 0.0
y_m = 0.0
heading_rad = 2.3648

[target]
kind = "radial-symbol"
x_m = {TARGET_XY_M[0]}
y_m = {TARGET_XY_M[1]}
heading_rad = 2.487

[[obstacles]]
shape = "wall"
x_m = -0.7700
y_m = -0.0031
x2_m = -0.6541
y2_m = 0.3378
thickness_m = 0.05
"""


@pytest.mark.timeout(600)
def test_the_guard_turns_the_base_away_from_a_short_wall_and_it_goes_past(tmp_path):
    p = tmp_path / "wall.toml"
    p.write_text(SCENE)
    summary, _ = execute(RunOptions(scenario=str(p), transport="inproc", out=tmp_path / "run",
                                    progress=False, plots=False))
    assert summary["safety"]["contacts"] == 0 and summary["contacts"] == 0, summary["safety"]
    events = [json.loads(line) for line in (tmp_path / "run" / "trace.jsonl").open()]
    guards = [e["sonar_guard"] for e in events if "sonar_guard" in e]
    assert guards and all(g["range_mm"] < g["r_r_mm"] for g in guards)
    assert any("turn_to_mrad" in g for g in guards)  # APPROACH: turned away before planning
    # past the wall (its middle is 0.95 m from the object) and on toward the object: before
    # the guard turned it away, the base stood 1.46 m from the object for the rest of the run
    dist = [math.hypot(e["x_m"] - TARGET_XY_M[0], e["y_m"] - TARGET_XY_M[1])
            for e in events if e.get("ev") == "truth"]
    assert min(dist) < 1.2, min(dist)
