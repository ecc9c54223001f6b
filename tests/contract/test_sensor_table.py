"""A sensor is declared once, in the board table (mcu_sim/avr/pinmap.py SENSORS), and the rig
wires it from there (docs/architecture.md, "Adding a sensor"): a toy sensor registered from the
test reaches board.h, the docs' table and the rig, coupled and polled."""

import dataclasses

import pytest
from rig_fakes import FakeMcu, FakePlant

from mobigrasp.cosim.lockstep import Done
from mobigrasp.cosim.plant import Plant
from mobigrasp.cosim.rig import Rig, RigConfig
from mobigrasp.mcu_sim.avr import pinmap
from mobigrasp.mcu_sim.backend import McuBackend
from mobigrasp.protocol.messages import Telemetry

BUMPER = pinmap.Sensor("bumper", ("BUMPER",), "a toy: the bumper pressed from 12 ms on",
                       "bumper_pressed", "set_bumper", pinmap.COUPLED, ())
LIGHT = pinmap.Sensor("light", ("LIGHT0", "LIGHT1"), "a toy: the light of two cells",
                      "light_level", "set_light_provider", pinmap.POLLED, ())
TOY_PINS = (("BUMPER", "PA3", pinmap.GPIO, "toy bumper switch"),
            ("LIGHT0", "PF0", "ADC0", "toy light cell 0"), ("LIGHT1", "PF1", "ADC1", "toy cell 1"))


class ToyPlant(FakePlant):
    reads = 0

    def bumper_pressed(self):
        return (self.t_us >= 12_000,)

    def light_level(self, index):
        self.reads += 1
        return 100 * index + self.t_us // 1000


class ToyMcu(FakeMcu):
    def __init__(self):
        super().__init__(telemetry_period_us=10**9)  # sends nothing: the rig has no port
        self.bumper: list[tuple[int, bool]] = []
        self.light = None

    def set_bumper(self, pressed, t_us):
        self.bumper.append((t_us, pressed))

    def set_light_provider(self, provider):
        self.light = provider


@pytest.fixture
def toys(monkeypatch):
    monkeypatch.setattr(pinmap, "BOARD", pinmap.BOARD + TOY_PINS)
    monkeypatch.setattr(pinmap, "SENSORS", pinmap.SENSORS + (BUMPER, LIGHT))


def test_every_sensor_names_its_signals_plant_and_mcu_methods_and_telemetry_fields():
    assert pinmap.check() == []
    telemetry = {f.name for f in dataclasses.fields(Telemetry)}
    signals = set(pinmap.by_signal())
    for s in pinmap.SENSORS:
        assert set(s.signals) <= signals and s.feed in pinmap.FEEDS, s.name
        assert callable(getattr(Plant, s.plant_reading, None)), s.name
        assert callable(getattr(McuBackend, s.mcu_input, None)), s.name
        assert s.telemetry and set(s.telemetry) <= telemetry, s.name
    assert {s.name for s in pinmap.SENSORS} == {"wheel_encoders", "sonar"}


def test_a_toy_sensor_is_in_board_h_and_the_docs_table(toys):
    assert pinmap.check() == []
    h = pinmap.header()
    assert "#define BUMPER_PORT PORTA\n#define BUMPER_DDR DDRA" in h and "#define BUMPER_BIT 3" in h
    assert "/* bumper: BUMPER -> no telemetry field */" in h
    assert "/* light: LIGHT0 LIGHT1 -> no telemetry field */" in h
    assert "| `light` | `LIGHT0`, `LIGHT1` | a toy: the light of two cells | `light_level` -> " \
        "`set_light_provider` (polled) |" in pinmap.markdown()


def test_the_check_refuses_a_sensor_on_a_missing_or_taken_signal(monkeypatch):
    bad = (dataclasses.replace(BUMPER, signals=("NOWHERE",)),
           dataclasses.replace(BUMPER, name="sonar2", signals=("SONAR_ECHO",)),
           dataclasses.replace(BUMPER, name="late", signals=(), feed="yearly"))
    monkeypatch.setattr(pinmap, "SENSORS", pinmap.SENSORS + bad)
    problems = pinmap.check()
    assert "sensor bumper: NOWHERE is not a signal of BOARD" in problems
    assert "sensor sonar2: SONAR_ECHO is also sonar's" in problems
    assert any(p.startswith("sensor late: feed 'yearly'") for p in problems)
    assert len(problems) == 3


def test_the_rig_wires_the_toy_sensors_from_the_table(toys):
    mcu, plant = ToyMcu(), ToyPlant()
    rig = Rig(mcu, plant, port=None, config=RigConfig(quantum_us=5_000, couple_us=2_500))
    assert mcu.light is not None  # the polled one got its provider at once
    for _ in range(4):
        grant = rig.grant()
        rig.complete(Done(until_us=grant.until_us))
    # coupled: read at every coupling step and given with its time
    assert mcu.bumper == [(t, t >= 12_000) for t in range(2_500, 20_001, 2_500)]
    assert mcu.enc == tuple(plant.ticks)  # the encoders, wired the same way
    # polled: the plant as at the last coupling step (20 ms), read once per index there
    assert (mcu.light(1), mcu.light(0), mcu.light(1)) == (120, 20, 120)
    assert plant.reads == 2
