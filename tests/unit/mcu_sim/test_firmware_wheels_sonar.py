"""Wheel speed PI on encoder counts (against the wheels-in-the-air plant) and the sonar cycle."""

import pytest

from mobigrasp.mcu_sim.bench_plant import TICKS_PER_MM, WheelsInTheAir
from mobigrasp.mcu_sim.firmware.sonar_task import NO_ECHO, width_to_mm
from mobigrasp.mcu_sim.firmware.wheel_pi import mmps_to_ticks_q8
from mobigrasp.mcu_sim.mcu import Mcu, McuConfig
from mobigrasp.mcu_sim.mcu_host import InProcessHost
from mobigrasp.protocol import PROTOCOL_VERSION, Hello, ParamSet, SetWheels

pytestmark = [pytest.mark.both_mcus, pytest.mark.simavr]


def drive(mcu, host, plant, ms, command):
    """Closed loop: plant stepped every 10 ms, SetWheels streamed at 50 Hz."""
    for k in range(ms // 10):
        if k % 2 == 0:
            host.send(command)
        ticks = plant.step(mcu.wheel_duty(), 10_000)
        mcu.set_encoder_ticks(*ticks, mcu.now_us + 10_000)
        host.run_ms(10)


def test_conversion_constant_matches_the_wheel_geometry():
    # 1 mm/s for 10 ms = 0.01 mm = 0.01 x TICKS_PER_MM ticks, in Q8.
    assert mmps_to_ticks_q8(1000) == pytest.approx(10 * TICKS_PER_MM * 256, rel=1e-3)
    assert mmps_to_ticks_q8(-1000) == -mmps_to_ticks_q8(1000)


@pytest.mark.parametrize(("left", "right"), [(300, 300), (-250, 400), (100, -100)])
def test_pi_tracks_speed_targets(left, right):
    mcu = Mcu()
    host = InProcessHost(mcu)
    host.send(Hello(PROTOCOL_VERSION, "t", 0))
    plant = WheelsInTheAir()
    drive(mcu, host, plant, 1500, SetWheels(left, right))
    assert plant.speed_mmps[0] == pytest.approx(left, rel=0.03, abs=3)
    assert plant.speed_mmps[1] == pytest.approx(right, rel=0.03, abs=3)
    tel = host.telemetry()[-1]  # sent at most 20 ms (+ line time) before the end
    lag_ticks = 0.03 * max(abs(left), abs(right)) * TICKS_PER_MM
    assert tel.enc_left == pytest.approx(plant.ticks()[0], abs=lag_ticks)
    assert tel.enc_right == pytest.approx(plant.ticks()[1], abs=lag_ticks)


def test_speed_above_the_parameter_is_clamped_and_counted():
    mcu = Mcu(McuConfig(params={"wheel_max_mmps": 200}))
    host = InProcessHost(mcu)
    host.send(Hello(PROTOCOL_VERSION, "t", 0))
    plant = WheelsInTheAir()
    drive(mcu, host, plant, 1000, SetWheels(600, 150))
    assert plant.speed_mmps[0] == pytest.approx(200, rel=0.05)
    assert mcu.limit_hits() == 50


def test_zero_target_keeps_the_bridge_off():
    mcu = Mcu()
    host = InProcessHost(mcu)
    host.send(Hello(PROTOCOL_VERSION, "t", 0))
    drive(mcu, host, WheelsInTheAir(), 300, SetWheels(0, 0))
    assert mcu.wheel_duty() == (0, 0)


def test_sonars_are_polled_in_turn_and_report_range_or_no_echo(mcu_backend):
    ranges = [0.30, 0.80, 1.50, 2.40, 3.00]
    mcu = Mcu()
    mcu.set_sonar_provider(lambda i: ranges[i])
    host = InProcessHost(mcu)
    # five 30 ms slots, plus the telemetry after the last; on the ELF the first cycle's slot 0
    # overlaps the end of the start-up and reports no echo, so sonar 0 is read a cycle later
    host.run_ms(350 if mcu_backend == "simavr" else 200)
    got = host.telemetry()[-1].sonar_mm
    for i in range(4):
        assert abs(got[i] - ranges[i] * 1000) <= 1, (i, got)
    assert got[4] == NO_ECHO  # beyond 2.5 m
    assert width_to_mm(5831) == 1000


def test_sonar_count_parameter_limits_the_cycle():
    mcu = Mcu()
    pinged = []  # the board asks for a range at each trigger pulse
    mcu.set_sonar_provider(lambda i: pinged.append(i) or 1.0)
    host = InProcessHost(mcu)
    host.send(Hello(PROTOCOL_VERSION, "t", 0), seq=0)
    host.send(ParamSet(6, 2), seq=1)
    host.run_ms(300)
    got = host.telemetry()[-1].sonar_mm
    assert all(abs(g - 1000) <= 1 for g in got[:2]) and got[2:] == (NO_ECHO,) * 3
    assert 5 <= len(pinged) <= 1 + 300 // 30
    assert set(pinged[-4:]) == {0, 1}
