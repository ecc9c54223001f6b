"""emulated_robot(scenario) with the wall clock: sim's session (services/sim_job.py) in a thread
of the test's process; bad options are refused before anything is served."""

import pytest

from mobigrasp.testing.served_robot import RobotDidNotStart


@pytest.mark.parametrize("scenario,kw,said", [
    ("no-such-scenario", {}, "unknown scenario 'no-such-scenario'"),
    ("paper000-exp1", {"mcu": "z80"}, "--mcu must be one of"),
    ("paper000-exp1", {"faults": ("uart_drop_rate=2",)}, "uart_drop_rate"),
    ("paper000-exp1", {"time_limit_s": -1.0}, "--time-limit-s"),
])
def test_bad_options_are_refused_with_sims_line_and_serve_nothing(emulated_robot, tmp_path,
                                                                  scenario, kw, said):
    with pytest.raises(RobotDidNotStart) as err:
        emulated_robot(scenario, **kw)
    assert said in str(err.value) and "\n" not in str(err.value)
    assert not (tmp_path / "sim-0" / "summary.json").exists()
