"""``mobigrasp scenarios``: list the shipped scenarios (name, method, target, obstacles, limit)."""

from __future__ import annotations

import argparse


def _run(args: argparse.Namespace) -> int:
    from mobigrasp.services.run_job import BadInput, resolve_scenario, shipped_scenarios

    print(f"{'name':<28} {'method':<6} {'target':<14} {'obstacles':>9} {'moving':>6} "
          f"{'limit_s':>7}")
    bad = 0
    for path in shipped_scenarios():
        try:
            _, sc = resolve_scenario(str(path))
        except BadInput as exc:
            print(f"{path.stem:<28} INVALID: {exc}")
            bad += 1
            continue
        print(f"{path.stem:<28} {sc.meta.method:<6} {sc.target.kind:<14} "
              f"{len(sc.obstacles):>9} {'yes' if sc.target.path else 'no':>6} "
              f"{sc.meta.time_limit_s:>7.0f}")
    return 2 if bad else 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``scenarios`` subcommand."""
    p = sub.add_parser("scenarios", help="list the shipped scenarios")
    p.set_defaults(func=_run)
