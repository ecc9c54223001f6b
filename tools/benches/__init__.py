"""Benchmarks of ``mobigrasp bench NAME``: each module has NAME, HELP and run(args) -> dict."""

from __future__ import annotations

from pathlib import Path


class BenchInputError(ValueError):
    """A bad option of a benchmark (the message names it): ``mobigrasp bench`` exits 2."""


def json_path(args, name: str) -> Path:
    """Where ``bench NAME`` writes its figures: ``--json``, else bench-results/NAME.json."""
    return args.json or Path("bench-results") / f"{name}.json"


def check_json_path(path: Path) -> None:
    """BenchInputError when the figures could not be written at ``path`` (found before the
    benchmark runs, not after)."""
    if path.is_dir():
        raise BenchInputError(f"--json {path} is a folder, not a file")
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise BenchInputError(f"--json {path}: {parent} is a file, not a folder")
            break
