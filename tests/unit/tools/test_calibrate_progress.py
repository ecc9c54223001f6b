"""``mobigrasp calibrate`` shows its progress as campaigns and the bench loop do: done/total,
elapsed and the time left, for the corpus recording and for the emulation; ``-q`` shows none.
The recording and the emulation are stand-ins that report steps and move a fake clock: the
lines are the command's, nothing sleeps."""

from __future__ import annotations

import functools

import pytest

from mobigrasp.tools import progress as progress_module
from mobigrasp.tools.cli import main

RESULT = {"stages": {}, "commit": "abc", "line_fill_cycles": 40, "frames": 0}


class FakeClock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


@pytest.fixture
def fake_calibration(monkeypatch, tmp_path):
    """The command with a recording of 3 scenarios (10 s each) and an emulation of 4 frames
    and 2 planner calls (5 s each) on a fake clock; every progress line shown."""
    from mobigrasp.calib import calibrate
    from mobigrasp.services import corpus

    clock = FakeClock()
    monkeypatch.setattr(progress_module, "StepProgress",
                        functools.partial(progress_module.StepProgress, clock=clock,
                                          interval_s=0))
    monkeypatch.setattr(calibrate, "default_path", lambda: tmp_path / "calibration.json")

    def record(out, scenarios, time_limit_s=None, progress=None):
        for k, name in enumerate(scenarios[:3]):
            clock.t += 10.0
            progress(k + 1, 3, f"{name}: 12 frames")
        return {"scenarios": [], "frames": []}

    def emulate(folder, per, fill, progress=None, on_step=None, record=None, scenarios=None):
        for k in range(6):
            clock.t += 5.0
            on_step(k + 1, 6, f"frame f{k}" if k < 4 else f"planner call p{k}")
        return dict(RESULT)

    monkeypatch.setattr(corpus, "record", record)
    monkeypatch.setattr(calibrate, "calibrate", emulate)
    return clock


def test_calibrate_shows_done_total_elapsed_and_time_left(fake_calibration, capsys):
    assert main(["calibrate"]) == 0
    lines = capsys.readouterr().err.splitlines()
    rec = [ln for ln in lines if ln.startswith("calibrate: corpus of the shipped scenarios:")]
    emu = [ln for ln in lines if ln.startswith("calibrate: emulated:")]
    assert rec[0].endswith(": 2/3 scenarios  paper000-exp2: 12 frames, elapsed 0m20s, "
                           "~0m10s left"), rec
    assert rec[-1].endswith(": 3/3 scenarios  paper001-sim1: 12 frames, elapsed 0m30s"), rec
    assert emu[0] == ("calibrate: emulated: 2/6 frames and planner calls  frame f1, "
                      "elapsed 0m10s, ~0m20s left")
    assert emu[-1] == ("calibrate: emulated: 6/6 frames and planner calls  planner call p5, "
                       "elapsed 0m30s")
    # the time left until the last step
    assert all(("left" in ln) is (" 3/3 " not in ln) for ln in rec)
    assert all(("left" in ln) is (" 6/6 " not in ln) for ln in emu)
    assert len(lines) == len(rec) + len(emu)


def test_calibrate_quiet_shows_no_progress(fake_calibration, capsys):
    assert main(["calibrate", "-q"]) == 0
    assert capsys.readouterr().err == ""
