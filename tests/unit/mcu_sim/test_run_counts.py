"""The run's counts of the plant (docs/task.md "The run's counts"): the longest stand-still of
the search and the approach, and what ends it."""

import pytest
from test_world_base import MIN_SCENARIO

from mobigrasp.cosim.rig_plant import WorldPlant
from mobigrasp.host.task import REGISTRY
from mobigrasp.mcu_sim.world.scenario import loads_scenario


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
