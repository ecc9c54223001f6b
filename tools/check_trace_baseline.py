"""Check that an optimisation changed no traced bit: run the shipped scenarios in process and
compare each run's ``trace_sha256`` with a baseline file written before the change.

    python -m mobigrasp.tools.check_trace_baseline --write /tmp/base.json   # before the change
    python -m tools.check_trace_baseline --check /tmp/base.json   # after it: exit 1 on a diff

The trace holds every host event, the modelled ARM9 load (from the OpCounts) and the ground
truth, so an equal sha means the same behaviour; wall times are printed for information only.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

SCENARIOS = ("paper000-exp1", "paper000-exp2", "paper001-sim1", "paper001-sim2",
             "paper002-cylinder-moving", "paper002-marker")


def run_one(name: str, time_limit_s: float, out_root: Path,
            mcu: str = "python") -> tuple[str, float]:
    """(trace_sha256, wall seconds of the whole run) of one in-process run."""
    from mobigrasp.services.run_job import RunOptions, execute

    t0 = time.perf_counter()
    summary, _ = execute(RunOptions(scenario=name, transport="inproc", speed=None,
                                    out=out_root / name, progress=False, plots=False,
                                    time_limit_s=time_limit_s, mcu=mcu))
    wall = time.perf_counter() - t0
    if summary.get("error"):
        raise RuntimeError(f"{name}: run crashed: {summary['error']}")
    return str(summary["trace_sha256"]), wall


def main(argv: list[str] | None = None) -> int:
    """Write or check a baseline; returns the exit code (1 when a sha differs)."""
    ap = argparse.ArgumentParser(prog="check_trace_baseline", description=__doc__.split("\n")[0])
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--write", type=Path, help="write the shas of this tree to FILE")
    mode.add_argument("--check", type=Path, help="compare the shas of this tree with FILE")
    ap.add_argument("--time-limit-s", type=float, default=20.0)
    ap.add_argument("--scenario", action="append", help="only these (repeat); default all six")
    ap.add_argument("--mcu", default="python", help="MCU backend of the runs (python, native)")
    args = ap.parse_args(argv)
    names = tuple(args.scenario or SCENARIOS)
    base: dict = {}
    if args.check is not None:
        try:
            base = json.loads(args.check.read_text())
        except (OSError, ValueError) as exc:
            print(f"cannot read baseline {args.check}: {exc}", file=sys.stderr)
            return 2
        if base.get("time_limit_s") != args.time_limit_s:
            print(f"baseline was written with --time-limit-s {base.get('time_limit_s')}, "
                  f"not {args.time_limit_s}", file=sys.stderr)
            return 2
    shas: dict[str, str] = {}
    walls: dict[str, float] = {}
    failed = 0
    with tempfile.TemporaryDirectory(prefix="trace-baseline-") as tmp:
        for name in names:
            sha, wall = run_one(name, args.time_limit_s, Path(tmp), args.mcu)
            shas[name], walls[name] = sha, round(wall, 3)
            line = f"{name:26s} {sha[:16]}  {wall:6.2f} s"
            if args.check is not None:
                want = base.get("shas", {}).get(name)
                same = want == sha
                failed += not same
                old = base.get("wall_s", {}).get(name)
                line += ("  SAME" if same else f"  DIFF (baseline {str(want)[:16]})")
                if old:
                    line += f"  baseline {old:6.2f} s"
            print(line, flush=True)
    if args.write is not None:
        args.write.write_text(json.dumps({"time_limit_s": args.time_limit_s, "shas": shas,
                                          "wall_s": walls}, indent=2, sort_keys=True) + "\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
