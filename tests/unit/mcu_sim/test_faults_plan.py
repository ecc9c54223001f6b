"""The [faults] schema: scenario files and --fault KEY=VALUE, same checks and errors."""

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.host.task import REGISTRY
from mobigrasp.mcu_sim.faults.plan import (
    FAULT_KEYS,
    FaultError,
    FaultPlan,
    MotorFail,
    SonarFail,
    Window,
    parse_fault_overrides,
    parse_faults,
)
from mobigrasp.mcu_sim.world.scenario import ScenarioError, loads_scenario

BASE = """
[scenario]
name = "f"
method = "000"
seed = 1
time_limit_s = 10
[robot]
x_m = 0
y_m = 0
heading_rad = 0
[target]
kind = "radial-symbol"
x_m = 1
y_m = 0
heading_rad = 0
"""

FULL = BASE + """
[faults]
uart_bit_error_rate = 1e-3
uart_drop_rate = 0.01
uart_latency_us = 2000
uart_burst = { start_s = 3.0, duration_s = 0.5 }
camera_drop_rate = 0.2
camera_noise_std = 4.0
host_stall = { at_s = 5, duration_s = 0.3 }
host_crash_at_s = 12.5
mcu_reset_at_s = 7
motor_fail = { wheel = "right", at_s = 9 }
sonar_fail = { index = 2, at_s = 1 }
encoder_slip = 0.05
"""


def test_every_key_parses_into_the_plan():
    plan = loads_scenario(FULL, "full.toml", methods=REGISTRY).faults
    assert plan == FaultPlan(
        uart_bit_error_rate=1e-3, uart_drop_rate=0.01, uart_latency_us=2000,
        uart_burst=Window(3.0, 0.5), camera_drop_rate=0.2, camera_noise_std=4.0,
        host_stall=Window(5.0, 0.3), host_crash_at_s=12.5, mcu_reset_at_s=7.0,
        motor_fail=MotorFail("right", 9.0), sonar_fail=SonarFail(2, 1.0), encoder_slip=0.05)
    assert set(plan.as_table()) == set(FAULT_KEYS)
    assert plan.active()


def test_no_faults_section_means_no_fault():
    plan = loads_scenario(BASE, "b.toml", methods=REGISTRY).faults
    assert plan == FaultPlan() and not plan.active() and plan.to_toml() == ""


@pytest.mark.parametrize("line, fragments", [
    ("uart_bit_errors = 1e-3", ["faults.uart_bit_errors: unknown key", "uart_bit_error_rate"]),
    ("uart_bit_error_rate = 0.7", ["faults.uart_bit_error_rate", "[0, 0.5]", "0.7"]),
    ("uart_drop_rate = -0.1", ["faults.uart_drop_rate", "[0, 1]"]),
    ('uart_drop_rate = "high"', ["faults.uart_drop_rate", "str"]),
    ("uart_latency_us = 1.5", ["faults.uart_latency_us", "an integer"]),
    ("uart_latency_us = true", ["faults.uart_latency_us", "an integer", "bool"]),
    ("uart_burst = 3", ["faults.uart_burst", "a table with start_s, duration_s"]),
    ("uart_burst = { start_s = 1 }", ["faults.uart_burst.duration_s", "missing"]),
    ("uart_burst = { start_s = 1, duration_s = 1, end_s = 2 }",
     ["faults.uart_burst.end_s: unknown key"]),
    ("host_stall = { at_s = -1, duration_s = 1 }",
     ["faults.host_stall.at_s", "[0, 1e+06]", "-1"]),
    ("host_crash_at_s = nan", ["faults.host_crash_at_s", "nan"]),
    ("mcu_reset_at_s = inf", ["faults.mcu_reset_at_s"]),
    ('motor_fail = { wheel = "middle", at_s = 1 }', ["faults.motor_fail.wheel", '"left"']),
    ("sonar_fail = { index = 5, at_s = 1 }", ["faults.sonar_fail.index", "[0, 4]"]),
    ("encoder_slip = 1.5", ["faults.encoder_slip", "[0, 1]"]),
    ("camera_noise_std = 300", ["faults.camera_noise_std", "[0, 255]"]),
])
def test_bad_values_name_file_key_and_expectation(line, fragments):
    with pytest.raises(ScenarioError) as e:
        loads_scenario(BASE + "[faults]\n" + line + "\n", "bad.toml", methods=REGISTRY)
    msg = str(e.value)
    assert msg.startswith("bad.toml: "), msg
    for f in fragments:
        assert f in msg, msg


def test_command_line_overrides_with_dotted_keys():
    plan = parse_fault_overrides(["uart_bit_error_rate=1e-3", "uart_burst.start_s=3",
                                  "uart_burst.duration_s=0.25", "motor_fail.wheel=left",
                                  "motor_fail.at_s=2", "sonar_fail.index=4",
                                  "sonar_fail.at_s=0", "uart_latency_us=500"])
    assert plan.uart_bit_error_rate == 1e-3 and plan.uart_latency_us == 500
    assert plan.uart_burst == Window(3.0, 0.25)
    assert plan.motor_fail == MotorFail("left", 2.0) and plan.sonar_fail == SonarFail(4, 0.0)


def test_overrides_apply_on_top_of_the_scenario_plan():
    base = loads_scenario(FULL, "full.toml", methods=REGISTRY).faults
    plan = parse_fault_overrides(["uart_burst.duration_s=2", "encoder_slip=0"], base)
    assert plan.uart_burst == Window(3.0, 2.0)  # start kept from the file
    assert plan.encoder_slip == 0.0 and plan.host_crash_at_s == 12.5


@pytest.mark.parametrize("items, fragment", [
    (["uart_bit_error_rate"], "expected KEY=VALUE"),
    (["=3"], "both parts"),
    (["uart_bit_error_rate=lots"], "faults.uart_bit_error_rate"),
    (["warp_drive=1"], "faults.warp_drive: unknown key"),
    (["warp.start_s=1"], "faults.warp: unknown key"),
    (["uart_burst.start_s=1"], "faults.uart_burst.duration_s"),
    (["uart_burst.begin=1", "uart_burst.duration_s=1"], "faults.uart_burst.begin: unknown key"),
    (["sonar_fail.index=1.5", "sonar_fail.at_s=1"], "faults.sonar_fail.index"),
])
def test_bad_overrides_are_clear_errors(items, fragment):
    with pytest.raises(FaultError) as e:
        parse_fault_overrides(items)
    assert str(e.value).startswith("--fault: ") and fragment in str(e.value), str(e.value)


plans = st.builds(
    FaultPlan,
    uart_bit_error_rate=st.sampled_from([0.0, 1e-4, 1e-3, 0.5]),
    uart_drop_rate=st.floats(0, 1), uart_latency_us=st.integers(0, 10_000_000),
    uart_burst=st.none() | st.builds(Window, st.floats(0, 1e3), st.floats(0, 1e3)),
    camera_noise_std=st.floats(0, 255),
    host_crash_at_s=st.none() | st.floats(0, 1e5),
    motor_fail=st.none() | st.builds(MotorFail, st.sampled_from(["left", "right"]),
                                     st.floats(0, 100)),
    sonar_fail=st.none() | st.builds(SonarFail, st.integers(0, 4), st.floats(0, 100)),
    encoder_slip=st.floats(0, 1),
)


@examples(100)
@given(plans)
def test_toml_and_command_line_round_trip(plan):
    assert loads_scenario(BASE + plan.to_toml(), "rt.toml", methods=REGISTRY).faults == plan
    items = []
    for key, value in plan.as_table().items():
        if isinstance(value, dict):
            items += [f"{key}.{k}={v}" for k, v in value.items()]
        else:
            items.append(f"{key}={value!r}")
    assert parse_fault_overrides(items) == plan


def test_parse_faults_rejects_a_non_table():
    with pytest.raises(FaultError, match="src: faults: expected a table"):
        parse_faults([1, 2], "src")


def test_every_key_is_documented():
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[3] / "docs" / "faults.md").read_text()
    for key in FAULT_KEYS:
        assert f"| `{key}` |" in doc, key
