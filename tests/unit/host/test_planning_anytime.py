"""A plan charged in slices of the control steps (host/planning/anytime.py), and the 001 task
taking its path in the step of the last slice, no control step charged more than a slice."""

import pytest

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.planning.anytime import PLAN_SLICE_US, PlanJob
from mobigrasp.host.task import Task, TaskInputs


def test_a_plan_is_charged_slice_by_slice_to_the_microsecond():
    ops = OpCounts(alu=400 * 20_500)  # 20.5 ms of ARM9 time
    job = PlanJob.start("path", {"reason": "ok"}, ops, slice_us=8_000)
    assert job.slices() == 3 and not job.done
    charged = [job.step().time_us() for _ in range(3)]
    assert charged == [8_000, 8_000, 4_500] and job.done and job.slices() == 0
    assert job.step().time_us() == 0  # nothing more to charge
    with pytest.raises(ValueError):
        PlanJob.start(None, None, ops, slice_us=0)


def _inputs(t):
    return TaskInputs(sonar_mm=(2500,) * 5)


def test_001_first_plan_takes_its_path_after_its_slices():
    task = Task("001", {"object_xy_mm": [2500, 0], "sonar_sweep_us": 0})
    out, t, plan = None, 0, None
    while plan is None and t < 400_000:
        out = task.step(t, _inputs(t))
        plan = (out.detail or {}).get("plan")
        t += 20_000
    assert plan is not None and plan["plan_arm9_us"] > PLAN_SLICE_US  # more than one slice
    slices = -(-plan["plan_arm9_us"] // PLAN_SLICE_US)
    steps = [out]
    for _ in range(slices - 1):
        steps.append(task.step(t, _inputs(t)))
        t += 20_000
    for o in steps:  # never more than a slice in a step (+ the step's own work)
        assert o.ops.time_us() <= PLAN_SLICE_US + 1_000
    for o in steps[:-1]:  # planning: standing
        assert o.wheels_mmps == (0, 0)
    assert steps[-1].wheels_mmps != (0, 0)  # the path, in the step of the last slice
