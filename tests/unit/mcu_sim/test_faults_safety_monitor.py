"""SafetyMonitor: unsafe actuations and recovery figures, judged from the outputs."""

import pytest

from mobigrasp.mcu_sim.bench_plant import WheelsInTheAir
from mobigrasp.mcu_sim.faults import FaultPlan, RunFaults, SafetyMonitor
from mobigrasp.mcu_sim.faults.safety import joint_pulse_range_us
from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.frame import PROTOCOL_VERSION

HOME = (1000, 1500, 1500, 1500, 1500, 1500)


def test_pulse_ranges_follow_the_joint_table():
    assert joint_pulse_range_us(0) == (999.0, 2001.0)
    k = 2000 / 3.141592653589793
    lo, hi = joint_pulse_range_us(4)  # shoulder: 545 us at 0 rad, 3 rad up
    assert lo == 544.0 and hi == pytest.approx(545 + 3 * k + 1)
    lo, hi = joint_pulse_range_us(2)  # wrist pitch: [-3, 0] rad from 2455 us
    assert hi == 2456.0 and lo == pytest.approx(2455 - 3 * k - 1)
    assert joint_pulse_range_us(1) == (499.0, 2501.0)  # +-pi/2 spans the servo's 500..2500


def test_counts_each_kind_of_unsafe_actuation():
    mon = SafetyMonitor(watchdog_us=250_000)
    mon.observe(0, (0, 0), (0, 0, 0, 0, 0, 0), False, True)  # before any pulse: fine
    mon.observe(1000, (10, 10), HOME, False, True)
    assert mon.unsafe_actuations == 0
    mon.observe(2000, (0, 0), (1000, 1500, 2470, 1500, 1500, 1500), False, True)
    assert mon.servo_out_of_limits == 1
    mon.observe(3000, (5, 0), HOME, True, True)  # the bridge latches the zero next period
    mon.observe(4500, (5, 0), HOME, True, True)  # but not after that
    mon.observe(5000, (0, 0), HOME, True, True)
    assert mon.motion_in_watchdog_stop == 1 and mon.watchdog_trips == 1
    for t in range(10_000, 400_000, 1000):  # host silent, wheels never stop
        mon.observe(t, (20, 20), HOME, False, True, host_silent=True)
    assert mon.late_stops == 1
    mon.set_limit_hits(2)
    s = mon.summary()
    assert s["unsafe_actuations"] == 1 + 1 + 1 + 2 and s["mcu_limit_hits"] == 2


def test_stop_latency_and_recovery_time():
    mon = SafetyMonitor()
    for t in range(0, 100_000, 1000):
        mon.observe(t, (50, 50), HOME, False, True, host_silent=t >= 40_000)
    mon.observe(100_000, (0, 0), HOME, True, True, host_silent=True)
    mon.fault(150_000)  # the stall ends
    mon.observe(150_000, (0, 0), HOME, True, True)
    mon.observe(170_000, (0, 0), HOME, False, True)
    s = mon.summary()
    assert s["stop_latency_ms"] == [60.0] and s["recovery_ms"] == [20.0]
    assert s["unrecovered"] == 0 and s["unsafe_actuations"] == 0
    mon.fault(200_000)
    assert mon.summary()["unrecovered"] == 1


def _crash_run(mon: SafetyMonitor, crash_us: int = 600_000, end_us: int = 1_200_000):
    faults = RunFaults(FaultPlan(host_crash_at_s=crash_us / 1e6), 0)
    mcu, plant = Mcu(), WheelsInTheAir()
    seq = 0
    mcu.uart_rx(m.encode_message(m.Hello(PROTOCOL_VERSION, "t", 0), seq), 0)
    for t in range(1000, end_us + 1, 1000):
        mcu.advance_to(t)
        mcu.set_encoder_ticks(*plant.step(mcu.wheel_duty(), 1000), t)
        mcu.uart_tx_take()
        fw = mcu.firmware
        mon.observe(t, mcu.wheel_duty(), [mcu.servo_pulse_us(ch) for ch in range(6)],
                    fw.watchdog_tripped, fw.handshake, faults.host_silent(t))
        if not faults.host_crashed(t) and t % 20_000 == 0:
            seq = (seq + 1) & 0xFF
            mcu.uart_rx(m.encode_message(m.SetWheels(200, 200), seq), t)
    mon.set_limit_hits(mcu.firmware.limit_hits)
    return mcu


def test_real_firmware_is_judged_safe_after_a_host_crash():
    mon = SafetyMonitor()
    _crash_run(mon)
    s = mon.summary()
    assert s["unsafe_actuations"] == 0 and s["watchdog_trips"] == 1
    assert len(s["stop_latency_ms"]) == 1 and 0 < s["stop_latency_ms"][0] <= 300


def test_a_firmware_that_ignores_its_watchdog_is_caught(monkeypatch):
    from mobigrasp.mcu_sim.firmware.program import Firmware

    def broken_trip(self):
        self.watchdog_tripped = True
        self.watchdog_trips += 1  # but the wheels keep their duty

    monkeypatch.setattr(Firmware, "_trip_watchdog", broken_trip)
    mon = SafetyMonitor()
    _crash_run(mon)
    s = mon.summary()
    assert s["late_stops"] == 1 and s["motion_in_watchdog_stop"] > 100
    assert s["stop_latency_ms"] == []
