"""Ground-truth recorder: the world's true state sampled at a fixed simulated rate.

This is the only place truth goes (the run's trace and summary read it; the host never can:
host/ may not import mcu_sim, see the import-linter contracts). Samples are taken on the world's
10 ms ticks, so the rate must divide 100 Hz (100, 50, 25, 20, 10, ... Hz); sampling depends only
on simulated time, never on how the caller steps the world.

A sample is ``World.truth()``: base pose and velocity, joints, gripper opening, camera point,
object pose, attached flag, contact counts, minimum obstacle clearance so far, encoder counts.
"""

from __future__ import annotations

import json
import math
from typing import Any


class TruthRecorder:
    """Collects ``World.truth()`` every ``1/rate_hz`` s of simulated time."""

    def __init__(self, rate_hz: int, tick_us: int):
        if isinstance(rate_hz, bool) or not isinstance(rate_hz, int) or rate_hz <= 0:
            raise ValueError(f"TruthRecorder: rate_hz must be a positive int, got {rate_hz!r}")
        period_us = 1_000_000 // rate_hz
        if 1_000_000 % rate_hz or period_us % tick_us:
            raise ValueError(f"TruthRecorder: rate_hz={rate_hz} does not give a period that is a "
                             f"multiple of the world tick ({tick_us} us)")
        self.rate_hz = rate_hz
        self.period_us = period_us
        self.samples: list[dict[str, Any]] = []

    def on_tick(self, world, t_us: int) -> None:
        """Called by the world on every tick; keeps the ticks that fall on the sampling grid."""
        if t_us % self.period_us == 0:
            self.samples.append(world.truth())

    def jsonl_lines(self) -> list[str]:
        """One JSON object per sample (``{"type": "truth", ...}``), for the run's trace."""
        return [json.dumps({"type": "truth", **s}, sort_keys=True) for s in self.samples]

    def trace_lines(self, contact_events) -> list[str]:
        """Truth samples and contact episodes (``ContactEpisode`` list) merged in time order,
        an episode at its start (``end_us`` null while it lasts).

        Contacts are exact to the 1 ms physics step, samples are on the sampling grid; at equal
        times a sample comes first.
        """
        rows = [(s["t_us"], 0, {"type": "truth", **s}) for s in self.samples]
        rows += [(e.start_us, 1, {"type": "contact", "t_us": e.start_us, "end_us": e.end_us,
                                  "with": e.kind, "obstacle_index": e.index})
                 for e in contact_events]
        rows.sort(key=lambda r: (r[0], r[1]))
        return [json.dumps(r[2], sort_keys=True) for r in rows]

    def summary(self) -> dict[str, Any]:
        """Figures for summary.json: path length, final pose, contacts, clearance, grasp."""
        if not self.samples:
            return {"samples": 0}
        path_m = 0.0
        for a, b in zip(self.samples, self.samples[1:], strict=False):
            path_m += math.hypot(b["base"]["x_m"] - a["base"]["x_m"],
                                 b["base"]["y_m"] - a["base"]["y_m"])
        last = self.samples[-1]
        first = self.samples[0]
        max_lift = max(s["object"]["z_m"] for s in self.samples)
        return {
            "samples": len(self.samples),
            "rate_hz": self.rate_hz,
            "duration_s": (last["t_us"] - first["t_us"]) * 1e-6,
            "path_length_m": path_m,
            "final_base": last["base"],
            "final_object": last["object"],
            "grasped_at_end": last["attached"],
            "grasps": last["grasps"],
            "object_max_lift_m": max_lift,
            "collisions": last["collisions"],
            "min_clearance_m": last["min_clearance_m"],
            "max_speed_mps": max(abs(s["base"]["v_mps"]) for s in self.samples),
        }
