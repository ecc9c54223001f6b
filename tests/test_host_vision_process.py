"""The opt-in vision child of the lockstep host (tools/commands/host.py ForkedVision)."""

import numpy as np
import pytest

from host.budget import OpCounts
from tools.commands.host import ForkedVision


def _mean(rgb, k=1):
    return {"mean": int(rgb.mean()) * k}, OpCounts(alu=int(rgb.sum()))


def _bad(rgb):
    raise ValueError("bad frame")


def test_child_runs_the_detectors_with_the_snapshots_in_order():
    vision = ForkedVision({"a": _mean, "b": _mean, "bad": _bad})
    try:
        rgb = np.full((4, 5, 3), 7, np.uint8)
        out = vision.submit(["a", "b"], rgb, [(), (3,)]).result()
        assert out == [_mean(rgb), _mean(rgb, 3)]
        with pytest.raises(ValueError, match="bad frame"):
            vision.submit(["a", "bad"], rgb, [(), ()]).result()
        assert vision.submit(["b"], rgb, [(2,)]).result() == [_mean(rgb, 2)]  # still serving
    finally:
        vision.close()
