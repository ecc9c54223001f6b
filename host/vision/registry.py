"""The detector table: one row per marker detector, read by everything that lists detectors.

A row says where the detector lives (module and function), what it returns (a frozen dataclass
of its module), what it charges at least on a frame (``min_ops(height, width)`` of its module,
the lower bound of its modelled ARM9 time), how the host calls it (the camera intrinsics and the
arm pose it needs) and how its result becomes a target of the task (a ``sighting(result, f_px)``
function of its module giving pixel and depth, or none). The host app's detectors
(host/app_factory.py), the per-frame cost report (host/vision/cost_report.py), the detectors
each method's states run (host/task/), the vision bench and the accuracy harness all read
:data:`DETECTORS`; adding a detector is its own module plus one row here
(docs/architecture.md, "Adding a detector").
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

# How the host calls a detector, ``rgb`` first: "frame" = ``function(rgb)``; "camera" =
# ``function(rgb, f_px, u0_px, v0_px)``; "pose" = the module's ``detect_at_pose(rgb, joints_mrad,
# (f_px, u0_px, v0_px))``, for a detector that needs the camera's pitch and yaw.
CALLS = ("frame", "camera", "pose")


@dataclass(frozen=True)
class DetectorRow:
    """One detector: ``module.function(rgb, ...) -> (result | None, OpCounts)``."""

    name: str
    module: str  # dotted module path
    function: str  # the detector in that module
    result: str  # the frozen dataclass of the module the detector returns
    call: str = "frame"  # one of CALLS
    uses_grey: bool = True  # starts from host.vision.grey.to_grey (charged once per frame)
    min_ops: str = "min_ops"  # module function: counts charged at least, (height, width)
    sighting: str | None = "sighting"  # module function: result -> (u_q4, v_q4, depth_q4)
    ranging: str | None = None  # "module:function" of a separate ranging stage's counts
    # "module:function" (height, width) -> OpCounts of the front end the detector's counts
    # include and the detectors of a frame share (computed once a frame on the board)
    front_end: str | None = None

    def load(self) -> Any:
        """The detector's module (imported on first use)."""
        return importlib.import_module(self.module)

    def detect(self) -> Callable:
        """The detector function; ``fn(rgb)`` runs it with its defaults."""
        return getattr(self.load(), self.function)

    def result_type(self) -> type:
        """The result dataclass."""
        return getattr(self.load(), self.result)

    def min_ops_fn(self) -> Callable:
        """``(height, width) -> OpCounts``, what the detector charges at least."""
        return getattr(self.load(), self.min_ops)

    def sighting_fn(self) -> Callable | None:
        """``(result, f_px) -> (u_q4, v_q4, depth_mm_q4) | None``, or None for no target."""
        return getattr(self.load(), self.sighting) if self.sighting else None

    def ranging_fn(self) -> Callable | None:
        """``() -> OpCounts`` of the ranging stage that follows a result, or None."""
        return _function(self.ranging) if self.ranging else None

    def front_end_fn(self) -> Callable | None:
        """``(height, width) -> OpCounts`` of the shared front end, or None."""
        return _function(self.front_end) if self.front_end else None

    def host_call(self, rgb: Any, cam: tuple[int, int, int], q: tuple[int, ...] | None) -> Any:
        """Run the detector as the host does: ``cam`` = (f_px, u0_px, v0_px), ``q`` the six
        joint angles (mrad) for a "pose" detector (None for the others)."""
        fn = self.detect()
        if self.call == "frame":
            return fn(rgb)
        if self.call == "camera":
            return fn(rgb, *cam)
        return self.load().detect_at_pose(rgb, q, cam)


def _function(ref: str) -> Callable:
    """The function a "module:function" reference names."""
    mod, fn = ref.split(":")
    return getattr(importlib.import_module(mod), fn)


_V = "mobigrasp.host.vision."
_DARK = _V + "dark_blobs:front_end_min_ops"  # grey, dark mask, components (dark_blobs.py)

DETECTORS: dict[str, DetectorRow] = {row.name: row for row in (
    DetectorRow("radial_symbol", _V + "radial_symbol", "detect_radial_symbol", "RadialSymbol",
                call="camera", front_end=_DARK),
    DetectorRow("double_cross", _V + "double_cross", "detect_double_cross", "DoubleCrossResult",
                call="pose"),
    DetectorRow("dual_plus", _V + "dual_plus", "detect_dual_plus", "DualPlus", call="pose",
                front_end=_DARK),
    DetectorRow("spoke", _V + "spoke", "detect_spoke", "Spoke", sighting=None, front_end=_DARK),
    DetectorRow("red_cylinder", _V + "red_cylinder", "detect_red_cylinder", "RedCylinderResult",
                uses_grey=False, ranging="mobigrasp.host.ranging:locate_ring_pair_ops"),
    DetectorRow("red_roi", _V + "red_cylinder", "detect_red_roi", "RedRoi", uses_grey=False,
                min_ops="roi_min_ops", sighting="roi_sighting"),
    DetectorRow("held_fill", _V + "held_fill", "detect_held_fill", "HeldFill", uses_grey=False,
                sighting=None),
    DetectorRow("radial_cut", _V + "radial_symbol", "detect_radial_cut", "RadialCut",
                sighting=None, front_end=_DARK),
)}


def row(name: str) -> DetectorRow:
    """The row of ``name``; unknown name -> ValueError naming the known ones."""
    found = DETECTORS.get(name)
    if found is None:
        raise ValueError(f"unknown detector {name!r}; known: {sorted(DETECTORS)}")
    return found


def check(name: str, result: Any) -> Any:
    """``result`` if it is the result type of detector ``name``; TypeError otherwise (a
    detection of the wrong kind is counted and dropped by the task)."""
    if not isinstance(result, row(name).result_type()):
        raise TypeError(f"{name}: expected {row(name).result}, got {type(result).__name__}")
    return result
