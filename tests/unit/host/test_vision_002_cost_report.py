import numpy as np
import pytest

from mobigrasp.host.budget import OpCounts
from mobigrasp.host.vision import cost_report as cr
from mobigrasp.host.vision.grey import grey_cost


def test_budget_and_shares():
    assert cr.FRAME_BUDGET_US == 66_667
    one_ms = OpCounts(alu=400_000)  # 400k single-cycle ops = 1 ms at 400 MHz
    rep = cr.build_report([("a", one_ms), ("b", one_ms.scaled(2))])
    assert [s.time_us for s in rep.stages] == [1000, 2000]
    assert rep.total_us == 3000 and rep.total_cycles == 1_200_000
    assert rep.stages[0].share_permille == 15  # 1 ms of 66.667 ms
    assert rep.share_permille == 45 and not rep.over_budget
    big = cr.build_report([("x", OpCounts(alu=400_000 * 70))])
    assert big.over_budget and big.share_permille > 1000
    text = cr.format_report(rep)
    assert "total" in text and "66667" in text


def test_frame_cost_stages_and_grey_shared():
    rng = np.random.default_rng(0)
    rgb = rng.integers(0, 256, (240, 320, 3), dtype=np.uint8)
    rep, results = cr.frame_cost(rgb, ["double_cross", "red_cylinder"])
    names = [s.name for s in rep.stages]
    assert names[:3] == ["grey", "double_cross", "red_cylinder"]
    assert rep.stages[0].ops == grey_cost(240, 320)
    assert rep.total_cycles == sum(s.cycles for s in rep.stages)
    assert set(results) == {"double_cross", "red_cylinder"}
    # the double-cross stage is charged without the grey it computed itself
    from mobigrasp.host.vision.double_cross import detect_double_cross
    _, ops = detect_double_cross(rgb)
    assert rep.stages[1].cycles == ops.cycles() - grey_cost(240, 320).cycles()


def test_unknown_detector():
    with pytest.raises(ValueError, match="unknown"):
        cr.frame_cost(np.zeros((240, 320, 3), np.uint8), ["nope"])
