"""The run's counts of the plant (docs/task.md "The run's counts"): the longest stand-still of
the search and the approach, and what ends it."""

import pytest
from test_world_base import MIN_SCENARIO

from mobigrasp.cosim.rig_plant import WorldPlant
from mobigrasp.cosim.summary import world_figures
from mobigrasp.host.task import REGISTRY
from mobigrasp.mcu_sim.world.scenario import loads_scenario
from mobigrasp.services import campaign, loop_campaign


def _run(plant, until_us, duty=(0, 0), step_us=20_000):
    plant.world.set_wheel_duty(*duty)
    t = plant.world.t_us
    while t < until_us:
        t += step_us
        plant.step_to(t)
        plant.sample_path()


def test_stand_still_counts_the_longest_stop_until_the_base_arrives():
    plant = WorldPlant(loads_scenario(MIN_SCENARIO.format(heading=0.0, tx=1.5, ty=0.0, extra=""),
                                      "still.toml", methods=REGISTRY))
    _run(plant, 3_000_000)  # standing 3 s
    assert plant.stand_still_max_us == pytest.approx(3_000_000, abs=40_000)
    _run(plant, 3_500_000, duty=(150, 150))  # driving: the stand-still is over
    _run(plant, 5_000_000)  # a shorter stop later keeps the longest
    assert plant.stand_still_max_us < 3_400_000
    _run(plant, 9_000_000, duty=(-100, 100))  # turning in place is standing still
    still = plant.stand_still_max_us
    assert still > 5_000_000
    _run(plant, 9_500_000)
    plant.world.base.body.angle = plant.world.base.control.angle = 0.0  # face the object
    _run(plant, 14_000_000, duty=(200, 200))
    x, _, _ = plant.world.base.pose()
    assert 1.5 - x <= 0.6  # arrived: the grasp's own stops are not stand-stills
    still = plant.stand_still_max_us
    _run(plant, 20_000_000)
    assert plant.stand_still_max_us == still
    assert plant.final()["stand_still_max_s"] == still / 1e6


BOARD_POST_AHEAD = MIN_SCENARIO.replace('kind = "radial-symbol"', 'kind = "red-cylinder"').replace(
    'method = "000"', 'method = "002"')


@pytest.mark.parametrize(("text", "kind"), [
    # 000's object is the card on its post: the base runs into the object itself
    (MIN_SCENARIO.format(heading=0.0, tx=1.0, ty=0.0, extra=""), "target"),
    # 002's board faces away (heading 0): its post stands 0.17 m before the cylinder
    (BOARD_POST_AHEAD.format(heading=0.0, tx=1.0, ty=0.0, extra=""), "obstacle"),
])
def test_a_base_pushing_a_target_or_its_post_is_a_contact_the_bars_count(text, kind, tmp_path):
    """No contact of the base is the grasp's (docs/task.md "The run's counts"): the summary's
    ``contacts``, which the campaign's bars read, counts the episodes with the object and with
    a marker's post as it counts those with obstacles."""
    plant = WorldPlant(loads_scenario(text, "push.toml", methods=REGISTRY))
    _run(plant, 8_000_000, duty=(100, 100))
    figs = world_figures(plant.final())
    assert figs["contacts"] >= 1 and figs[f"contacts_{kind}"] == figs["contacts"]
    assert figs["contact_time_s"] > 0
    summary = {**figs, "success": True, "claimed_success": True, "status": "finished",
               "task_state": "DONE", "end_reason": "task_done"}
    assert campaign.row_of({"seed": 1}, summary)["collisions"] == figs["contacts"]
    job = {"method": "000", "seed": 1000, "generator": "v3", "transport": "inproc",
           "time_limit_s": 8.0, "host": "python", "scene": "push", "folder": str(tmp_path)}
    row = loop_campaign.row_of(job, summary)
    assert row["contacts"] == figs["contacts"] and not row["met_bar"]
