"""Per-frame ARM9 cost report by stage: grey, each detector, ranging.

Every kernel returns a host.budget.OpCounts; here they are turned into ARM920T cycles, modelled
time at 400 MHz and the share of the frame budget (one frame period: 66 667 µs at 15 fps).
Detectors that start from the grey image (they call host.vision.grey.to_grey themselves; the
``uses_grey`` column of host/vision/registry.py) are charged without it here, and the grey
conversion is one stage of its own: on the board the grey frame is computed once and shared by
all detectors of the frame.

Integer only: times in µs, shares in per mille.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from mobigrasp.host.budget import FCLK_HZ, OpCounts
from mobigrasp.host.vision.grey import grey_cost
from mobigrasp.host.vision.registry import DETECTORS

FPS = 15
FRAME_BUDGET_US = 1_000_000 // FPS + 1  # 66 667 µs, one frame period at 15 fps


@dataclass(frozen=True)
class StageCost:
    """One stage: its counts, ARM920T cycles, modelled µs and per mille of the frame budget."""

    name: str
    ops: OpCounts
    cycles: int
    time_us: int
    share_permille: int


@dataclass(frozen=True)
class FrameCostReport:
    """All stages of one frame and their total against the budget."""

    stages: tuple[StageCost, ...]
    total_cycles: int
    total_us: int
    budget_us: int
    share_permille: int

    @property
    def over_budget(self) -> bool:
        """True when the frame's work does not fit in one frame period."""
        return self.total_us > self.budget_us


def _minus(a: OpCounts, b: OpCounts) -> OpCounts:
    return OpCounts(**{f.name: max(0, getattr(a, f.name) - getattr(b, f.name))
                       for f in fields(a)})


def stage(name: str, ops: OpCounts, budget_us: int = FRAME_BUDGET_US) -> StageCost:
    """Cost one stage."""
    cyc = ops.cycles()
    t = ops.time_us()
    return StageCost(name, ops, cyc, t, (1000 * t + budget_us // 2) // budget_us)


def build_report(stages: list[tuple[str, OpCounts]],
                 budget_us: int = FRAME_BUDGET_US) -> FrameCostReport:
    """A report from (stage name, counts) pairs, in order."""
    costed = tuple(stage(n, o, budget_us) for n, o in stages)
    total = OpCounts()
    for _, o in stages:
        total += o
    cyc = total.cycles()
    t = -(-cyc * 1_000_000 // FCLK_HZ)
    return FrameCostReport(costed, cyc, t, budget_us, (1000 * t + budget_us // 2) // budget_us)


def frame_cost(rgb: np.ndarray, detectors: list[str], budget_us: int = FRAME_BUDGET_US
               ) -> tuple[FrameCostReport, dict[str, object]]:
    """Run the named detectors on one frame; the cost report and each detector's result.

    Unknown names raise ValueError. A detector's result with a ranging stage in its row
    (host/vision/registry.py) adds that stage.
    """
    unknown = [d for d in detectors if d not in DETECTORS]
    if unknown:
        raise ValueError(f"frame_cost: unknown detectors {unknown}; known: {sorted(DETECTORS)}")
    h, w = rgb.shape[:2]
    g_ops = grey_cost(h, w)
    stages: list[tuple[str, OpCounts]] = []
    if any(DETECTORS[d].uses_grey for d in detectors):
        stages.append(("grey", g_ops))
    results: dict[str, object] = {}
    for d in detectors:
        row = DETECTORS[d]
        res, ops = row.detect()(rgb)
        results[d] = res
        stages.append((d, _minus(ops, g_ops) if row.uses_grey else ops))
        ranging = row.ranging_fn()
        if res is not None and ranging is not None:
            stages.append((f"{d} ranging", ranging()))
    return build_report(stages, budget_us), results


def format_report(rep: FrameCostReport) -> str:
    """Plain-text table: stage, cycles, modelled ms, share of the frame budget."""
    lines = [f"{'stage':<24}{'cycles':>12}{'ms':>10}{'budget':>9}"]
    for s in rep.stages:
        lines.append(f"{s.name:<24}{s.cycles:>12}{s.time_us // 1000:>6}.{s.time_us % 1000:03d}"
                     f"{s.share_permille // 10:>6}.{s.share_permille % 10}%")
    lines.append(f"{'total':<24}{rep.total_cycles:>12}{rep.total_us // 1000:>6}."
                 f"{rep.total_us % 1000:03d}{rep.share_permille // 10:>6}."
                 f"{rep.share_permille % 10}%")
    lines.append(f"frame budget {rep.budget_us} us at {FPS} fps"
                 + ("  OVER BUDGET" if rep.over_budget else ""))
    return "\n".join(lines)
