"""How far the radial symbol is read against the camera gain (docs/markers.md, "Camera gain").

Twelve fixed views (``camera_views.radial_ahead``: the search camera 0.30 m up, the object
turned by 30 degrees from view to view, seen from a seeded direction with its centre within
60 x 40 px of the image centre, no clutter), the camera moved toward the symbol from 1.60 to
0.80 m in steps of 0.05 m; at each distance two frames (noise 3, motion blur 1 and 2 px) at each
gain. A view's reach at a gain is the farthest distance at which a frame is read with its depth
within 5 %; the table gives the median, least and largest reach of the twelve views.

Usage: ``python -m mobigrasp.tools.gain_reach [--hc 0.30] [--json out.json]``.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

from mobigrasp.host.vision.radial_symbol import detect_radial_symbol
from mobigrasp.mcu_sim.world import camera_views as cvv
from mobigrasp.mcu_sim.world.camera import CameraOptions, apply_options, render_clean

GAINS = (1.0, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8)
DISTS_M = tuple(round(0.80 + 0.05 * i, 2) for i in range(17))


def reach(gain: float, hc_m: float = 0.30, n_views: int = 12) -> list[float]:
    """The farthest distance (m) each view is read at ``gain`` (0.0: not read at all)."""
    rng = np.random.default_rng(5)
    out = []
    for i in range(n_views):
        beta = float(rng.uniform(-3.1, 3.1))
        du, dv = float(rng.uniform(-60, 60)), float(rng.uniform(-40, 40))
        seed = int(rng.integers(1 << 16))
        best = 0.0
        for d in DISTS_M:
            v = cvv.radial_ahead(d, 2 * math.pi * i / n_views, beta, hc_m, du, dv, seed)
            clean = render_clean(v.scene, v.cam_pos_w, v.R_wc, v.intr)
            y = v.truth["y_oc_mm"]
            for k in range(2):
                img = apply_options(clean, CameraOptions(noise_std=3.0, blur_px=1.0 + k,
                                                         brightness=gain),
                                    np.random.default_rng(seed + k))
                r, _ = detect_radial_symbol(img)
                if r is not None and abs(r.y_oc_mm - y) <= 0.05 * y:
                    best = max(best, d)
        out.append(best)
    return out


def _height_m(text: str) -> float:
    """--hc: a finite camera height of 0.05-2 m."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (math.isfinite(v) and 0.05 <= v <= 2.0):
        raise argparse.ArgumentTypeError(f"{text!r} is not a camera height of 0.05-2 m")
    return v


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hc", type=_height_m, default=0.30, help="camera height (m), 0.05-2")
    ap.add_argument("--json", default=None, help="write the reaches per gain here")
    args = ap.parse_args(argv)
    if args.json is not None:  # checked before minutes of rendering, not after
        out = Path(args.json)
        if out.is_dir() or not out.parent.is_dir():
            ap.error(f"--json {args.json}: not a file in an existing folder")
    rows = {}
    print("| gain | reach median (least-largest) |")
    print("|---|---|")
    for g in GAINS:
        far = reach(g, args.hc)
        rows[str(g)] = far
        print(f"| {g} | {np.median(far):.2f} m ({min(far):.2f}-{max(far):.2f}) |", flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
