"""The fault wrappers in the real closed loop, wired as services/run_job does, in process.

Short runs of paper000-exp1 (a few simulated seconds): a host crash stops the wheels within the
watchdog period + 50 ms and the arm is held; bit errors on both directions are seen by both
parsers and cause no unsafe actuation; a burst or a host stall trips the watchdog and the loop
recovers; after an MCU reset the host opens the session again.
"""

import pytest
from faulted_loop import faulted_loop

from mobigrasp.mcu_sim.faults import FaultPlan, Window


def _run(tmp_path, plan: FaultPlan, seconds: float, seed: int = 1):
    duties = []
    run = faulted_loop(tmp_path, plan, seconds, seed, session=lambda mcu, plant: {
        "on_quantum": lambda t: duties.append((t, mcu.inner.wheel_duty()))})
    return run.res, run.faults, run.safety, run.mcu.inner, duties, run.trace_path


def test_host_crash_in_the_loop_stops_wheels_and_is_recorded(tmp_path):
    crash_us = 1_000_000
    res, faults, safety, mcu, duties, trace = _run(
        tmp_path, FaultPlan(host_crash_at_s=crash_us / 1e6), 1.5)
    assert res.reason == "time_limit" and res.end_us == 1_500_000
    assert safety["unsafe_actuations"] == 0 and safety["late_stops"] == 0
    assert safety["watchdog_trips"] == 1 and mcu.firmware.watchdog_tripped
    assert len(safety["stop_latency_ms"]) == 1 and safety["stop_latency_ms"][0] <= 300.0
    assert all(d == (0, 0) for t, d in duties if t >= crash_us + 300_000)
    assert faults["host_quanta_skipped"] == 100  # 0.5 s of 5 ms quanta
    assert '"fault":"host_crash"' in trace.read_text()
    # telemetry at 50 Hz for 0.5 s that no one read, kept off the line (a pty would fill up)
    assert faults["mcu_bytes_unread_by_host"] > 25 * 30


def test_bit_errors_in_the_loop_are_caught_and_retransmitted(tmp_path):
    res, faults, safety, mcu, _, _ = _run(tmp_path, FaultPlan(uart_bit_error_rate=3e-3), 2.0)
    assert res.reason == "time_limit"
    assert faults["uart_to_mcu"]["bits_flipped"] > 0 and faults["uart_to_host"]["bits_flipped"] > 0
    assert mcu.stats()["corrupt_frames"] > 0  # the MCU's parser refused damaged frames
    assert res.host_stats["protocol"]["crc_errors"] > 0  # and so did the host's
    assert safety["unsafe_actuations"] == 0 and safety["watchdog_trips"] == 0


def test_uart_burst_trips_the_watchdog_and_recovers(tmp_path):
    res, faults, safety, mcu, _, _ = _run(
        tmp_path, FaultPlan(uart_burst=Window(start_s=0.6, duration_s=0.4)), 1.4)
    assert faults["uart_to_mcu"]["bytes_lost"] > 0 and faults["uart_to_host"]["bytes_lost"] > 0
    assert safety["watchdog_trips"] == 1 and safety["unsafe_actuations"] == 0
    assert not mcu.firmware.watchdog_tripped  # the host's frames fed it again after the burst
    assert len(safety["stop_latency_ms"]) == 1 and safety["stop_latency_ms"][0] <= 300.0
    assert len(safety["recovery_ms"]) == 1 and safety["recovery_ms"][0] <= 150.0


def test_mcu_reset_happens_at_its_time_and_is_safe(tmp_path):
    res, faults, safety, mcu, _, _ = _run(tmp_path, FaultPlan(mcu_reset_at_s=0.8), 1.4)
    assert faults["mcu_resets"] == 1
    assert safety["unsafe_actuations"] == 0
    # the host sees the reset in the telemetry (host/mcu_watch), says HELLO again and resumes
    assert mcu.firmware.handshake and safety["unrecovered"] == 0
    assert len(safety["recovery_ms"]) == 1 and safety["recovery_ms"][0] <= 100.0


@pytest.mark.slow
def test_host_crash_while_driving_stops_the_wheels_in_time(tmp_path):
    # find when paper000-exp1 drives, then crash the host in the middle of it (same seed: the
    # run is identical up to the crash)
    _, _, _, _, duties, _ = _run(tmp_path / "probe", FaultPlan(), 40.0)
    moving = [t for t, d in duties if d != (0, 0)]
    assert moving, "the robot never drove in 40 s"
    crash_us = moving[len(moving) // 2] // 5_000 * 5_000
    _, _, safety, _, duties, _ = _run(tmp_path / "crash", FaultPlan(host_crash_at_s=crash_us / 1e6),
                                      crash_us / 1e6 + 1.0)
    assert any(d != (0, 0) for t, d in duties if crash_us - 100_000 <= t <= crash_us)
    assert safety["late_stops"] == 0 and safety["unsafe_actuations"] == 0
    # from the last valid frame before the crash, so at most the watchdog period after it
    assert 0.0 < safety["stop_latency_ms"][0] <= 300.0
    assert all(d == (0, 0) for t, d in duties if t >= crash_us + 300_000)


@pytest.mark.parametrize("plan", [FaultPlan(), FaultPlan(camera_drop_rate=1.0)])
def test_camera_drop_all_frames_reach_no_host(tmp_path, plan):
    res, faults, _, _, _, _ = _run(tmp_path, plan, 0.5)
    received = res.host_stats.get("frames_received", 0)
    if plan.camera_drop_rate:
        assert received == 0 and faults["camera_frames_dropped"] == 8  # 0 .. 0.5 s at 15 fps
    else:
        assert received >= 7


def test_host_stall_trips_the_watchdog_and_the_host_resumes(tmp_path):
    res, faults, safety, mcu, _, trace = _run(
        tmp_path, FaultPlan(host_stall=Window(start_s=0.5, duration_s=0.5)), 1.5)
    assert faults["host_quanta_skipped"] == 100
    assert safety["watchdog_trips"] == 1 and safety["unsafe_actuations"] == 0
    assert len(safety["recovery_ms"]) == 1 and safety["recovery_ms"][0] <= 150.0
    assert not mcu.firmware.watchdog_tripped and mcu.firmware.handshake
    assert '"fault":"host_stall"' in trace.read_text()


@pytest.mark.slow
def test_host_crash_over_the_pty_runs_to_the_time_limit(tmp_path):
    # a crashed host process reads nothing: without the wrapper keeping the MCU's bytes off the
    # line the pty fills up after a few simulated seconds and the rig gives up
    from mobigrasp.services.run_job import RunOptions, execute

    summary, code = execute(RunOptions(scenario="paper000-exp1", transport="pty",
                                       out=tmp_path / "run", progress=False, plots=False,
                                       time_limit_s=30.0, faults=("host_crash_at_s=1",),
                                       after_crash_s=None))
    assert summary["status"] == "finished" and summary["end_reason"] == "time_limit", summary
    assert summary["safety"]["unsafe_actuations"] == 0 and summary["safety"]["watchdog_trips"] == 1
    assert summary["faults"]["mcu_bytes_unread_by_host"] > 50_000


def test_a_run_ends_two_seconds_after_a_host_crash(tmp_path):
    # the crashed host never comes back: the run ends once the MCU had 2 s to stop safely
    from mobigrasp.services.run_job import RunOptions, execute

    summary, code = execute(RunOptions(scenario="paper000-exp1", transport="inproc",
                                       out=tmp_path / "run", progress=False, plots=False,
                                       time_limit_s=30.0, faults=("host_crash_at_s=0.5",)))
    assert code == 1 and summary["end_reason"] == "host_crashed", summary
    assert summary["sim_time_s"] == pytest.approx(2.5, abs=0.01)
    assert summary["safety"]["watchdog_trips"] == 1 and summary["safety"]["late_stops"] == 0
