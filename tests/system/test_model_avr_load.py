"""The Python firmware model's AVR load (mcu_sim/firmware/cycles.py) against the ELF's under
simavr on the same scenario slice: within the tolerance docs/firmware.md states, and the model's
trace is the one without the load (the load is a report, not behaviour)."""

from __future__ import annotations

import shutil

import pytest

from mobigrasp.services.run_job import RunOptions, execute, shipped_scenarios

LOAD_TOLERANCE = 0.25  # |model - simavr| <= 25 % of simavr's, docs/firmware.md
SHIPPED = sorted(p.stem for p in shipped_scenarios())

needs_avr = pytest.mark.skipif(shutil.which("avr-gcc") is None,
                               reason="avr-gcc is missing (make firmware installs it)")


def _loads(name: str, tmp_path, **kw) -> tuple[int, int]:
    out = []
    for mcu in ("python", "simavr"):
        summary, _ = execute(RunOptions(scenario=name, out=tmp_path / mcu, progress=False,
                                        plots=False, transport="inproc", mcu=mcu, **kw))
        out.append(summary["mcu"]["avr_load_permille"])
    return out[0], out[1]


@needs_avr
@pytest.mark.parametrize("name", ["paper001-sim1", "paper002-marker"])
def test_the_models_load_is_near_simavrs_over_a_scenarios_first_seconds(name, tmp_path):
    # the start-up, the session's opening and the first moves (paper001-sim1 drives)
    model, avr = _loads(name, tmp_path, time_limit_s=3.0)
    assert 0 < avr and abs(model - avr) <= LOAD_TOLERANCE * avr, (model, avr)


@needs_avr
@pytest.mark.slow
@pytest.mark.timeout(900)
@pytest.mark.parametrize("name", SHIPPED)
def test_the_models_load_is_near_simavrs_over_a_whole_scenario(name, tmp_path):
    model, avr = _loads(name, tmp_path)
    assert 0 < avr and abs(model - avr) <= LOAD_TOLERANCE * avr, (model, avr)
