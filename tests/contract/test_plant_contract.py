"""One contract for every plant the rig can drive (mobigrasp.cosim.plant.Plant): the world, the
bench plant (wheels in the air), the fault wrapper around the world, and the test fake."""

import inspect

import numpy as np
import pytest
from rig_fakes import FakePlant

from mobigrasp.cosim.plant import Plant
from mobigrasp.cosim.rig_plant import WorldPlant
from mobigrasp.host.task import REGISTRY
from mobigrasp.mcu_sim.bench_plant import WheelsInTheAir
from mobigrasp.mcu_sim.faults.injectors import RunFaults
from mobigrasp.mcu_sim.faults.plan import FaultPlan
from mobigrasp.mcu_sim.faults.wrappers import FaultedPlant
from mobigrasp.mcu_sim.world.scenario import load_scenario
from mobigrasp.resources import data_dir

SCENARIO = data_dir("mobigrasp.scenarios") / "paper000-exp1.toml"
KINDS = ["world", "bench", "faulted:world", "fake"]
HAS_CAMERA = {"world": True, "bench": False, "faulted:world": True, "fake": True}


def _make(kind: str):
    if kind == "world":
        return WorldPlant(load_scenario(SCENARIO, methods=REGISTRY), 1)
    if kind == "bench":
        return WheelsInTheAir()
    if kind == "faulted:world":
        return FaultedPlant(WorldPlant(load_scenario(SCENARIO, methods=REGISTRY), 1),
                            RunFaults(FaultPlan(), 1))
    return FakePlant()


@pytest.fixture(params=KINDS)
def kind(request):
    return request.param


def test_every_method_of_the_interface_is_there(kind):
    plant = _make(kind)
    names = [n for n, _ in inspect.getmembers(Plant) if not n.startswith("_")]
    assert {"step_to", "encoder_ticks", "capture"} <= set(names)
    assert [n for n in names if not callable(getattr(plant, n, None))] == []


def test_duty_turns_the_wheels_forward_and_back(kind):
    plant = _make(kind)
    left0, right0 = plant.encoder_ticks()
    plant.set_wheel_duty(200, 200)
    for t in range(1_000, 301_000, 1_000):
        plant.step_to(t)
    left1, right1 = plant.encoder_ticks()
    assert left1 > left0 and right1 > right0
    plant.set_wheel_duty(-200, -200)
    for t in range(301_000, 901_000, 1_000):
        plant.step_to(t)
    left2, right2 = plant.encoder_ticks()
    assert left2 < left1 and right2 < right1


def test_servo_pulses_sonar_and_camera(kind):
    plant = _make(kind)
    for ch in range(6):
        plant.set_servo_pulse_us(ch, 1500)
    plant.step_to(20_000)
    for i in range(5):
        r = plant.sonar_range_m(i)
        assert r is None or 0.0 <= r < 10.0
    assert plant.sonar_range_m(99) is None
    frame = plant.capture(20_000)
    if not HAS_CAMERA[kind]:
        assert frame is None
        return
    assert isinstance(frame, np.ndarray) and frame.dtype == np.uint8
    assert frame.ndim == 3 and frame.shape[2] == 3
