"""``mobigrasp bench NAME [--json PATH]``: run a benchmark, print a table, write JSON.

Benchmarks live in ``tools/benches/<name>.py``; each defines ``NAME``, ``HELP``, optionally
``add_arguments(parser)``, and ``run(args) -> dict``. Keys carry units (``parse_mb_per_s``); where
a ratio is the point, the baseline is measured in the same run and stored next to it.
"""

from __future__ import annotations

import argparse
import importlib
import json
import pkgutil
import platform
import sys
from pathlib import Path

import mobigrasp.tools.benches
from mobigrasp.tools.benches import BenchInputError, check_json_path, json_path
from mobigrasp.tools.progress import add_common_options


def _benches() -> dict:
    found = {}
    for info in pkgutil.iter_modules(mobigrasp.tools.benches.__path__):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"mobigrasp.tools.benches.{info.name}")
        found[module.NAME] = module
    return found


def format_table(results: dict, prefix: str = "") -> list[str]:
    """Flatten nested result dicts into aligned ``key  value`` lines."""
    lines: list[str] = []
    for key, value in results.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            lines.extend(format_table(value, prefix=f"{name}."))
        elif isinstance(value, float):
            lines.append(f"{name:<48} {value:>14.4g}")
        else:
            lines.append(f"{name:<48} {value!s:>14}")
    return lines


def interpreter() -> dict:
    """Which Python ran the benchmark: the same code runs ~13 % faster on a distribution's
    optimised build than on a default source build (docs/cosim.md, "Measured"), so figures
    are compared only between runs of the same one."""
    return {"version": platform.python_version(),
            "implementation": platform.python_implementation(),
            "executable": getattr(sys, "_base_executable", sys.executable),
            "build": " ".join(platform.python_build()), "compiler": platform.python_compiler()}


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``bench`` subcommand and one sub-subcommand per benchmark."""
    parser = sub.add_parser("bench", help="run a benchmark; prints a table and writes JSON")
    inner = parser.add_subparsers(dest="bench_name", metavar="NAME", required=True)
    for name, module in sorted(_benches().items()):
        p = inner.add_parser(name, help=module.HELP, description=module.HELP)
        p.add_argument("--json", type=Path, default=None,
                       help=f"where to write the figures (default bench-results/{name}.json)")
        if hasattr(module, "add_arguments"):
            module.add_arguments(p)
        add_common_options(p)
        p.set_defaults(func=_runner(name, module))


def _runner(name: str, module):
    def run(args: argparse.Namespace) -> int:
        path = json_path(args, name)
        try:
            check_json_path(path)
            results = {**module.run(args), "python": interpreter()}
        except BenchInputError as exc:
            print(f"mobigrasp bench {name}: {exc}", file=sys.stderr)
            return 2
        print(f"mobigrasp bench {name}")
        for line in format_table(results):
            print("  " + line)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps({"bench": name, **results}, indent=2, sort_keys=True) + "\n")
        print(f"written {path}")
        return 0

    return run
