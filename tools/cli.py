"""Entry point of the ``mobigrasp`` command: parses arguments and dispatches to a subcommand.

Subcommands live in ``tools/commands/<name>.py`` and are discovered here, so that parallel work on
different commands never edits this file. Each module defines ``register(subparsers)`` which adds
its parser and sets ``func`` (a callable taking the parsed namespace and returning an exit code).
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from importlib.metadata import PackageNotFoundError, version
from typing import NoReturn

import mobigrasp.tools.commands
from mobigrasp.tools.progress import add_common_options, setup_logging

DESCRIPTION = "Embedded mobile manipulator of papers 000-002: host, emulated MCU, world."


class _Commands:
    """The subparsers action as the command modules see it: every parser it adds gets the
    one-line help as its description and the common ``-v/--verbose``, ``-q/--quiet`` options
    (a command that defines its own ``--quiet`` replaces that option string)."""

    def __init__(self, sub: argparse._SubParsersAction) -> None:
        self.sub = sub

    def add_parser(self, name: str, **kw) -> argparse.ArgumentParser:
        """``add_parser`` of argparse, plus the description and the common options."""
        if kw.get("help") and "description" not in kw:
            kw["description"] = kw["help"]
        kw.setdefault("conflict_handler", "resolve")
        parser = self.sub.add_parser(name, **kw)
        add_common_options(parser)
        return parser


class _Parser(argparse.ArgumentParser):
    """argparse with a refused option as one line on stderr (exit 2), naming the option and
    the value (escaped and cut by mobigrasp.mcu_sim.checks), not the usage text."""

    def error(self, message: str) -> NoReturn:
        from mobigrasp.mcu_sim.checks import SHOWN_CHARS

        text = message.encode("ascii", "backslashreplace").decode("ascii")
        cut = 2 * SHOWN_CHARS + 80  # the option, what it expects and the value
        text = text if len(text) <= cut else text[:cut - 3] + "..."
        self.exit(2, f"{self.prog}: {text} (--help for usage)\n")


def _version() -> str:
    try:
        return version("mobigrasp")
    except PackageNotFoundError:  # running from a source tree without an install
        return "0+unknown"


def build_parser() -> argparse.ArgumentParser:
    """Build the full argument parser, one subparser per module under ``tools/commands``."""
    parser = _Parser(prog="mobigrasp", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"mobigrasp {_version()}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    commands = pkgutil.iter_modules(mobigrasp.tools.commands.__path__)
    for info in sorted(commands, key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        try:
            importlib.import_module(f"mobigrasp.tools.commands.{info.name}").register(
                _Commands(sub))
        except ModuleNotFoundError as exc:  # a command of an extra that is not installed
            if missing_extra(exc) is None:
                raise
            _unavailable(sub, info.name.replace("_", "-"), exc)
    return parser


# the modules each extra of pyproject.toml brings, for a one-line hint when one is missing
EXTRA_OF_MODULE = {"numpy": "sim", "cv2": "sim", "pymunk": "sim", "mcap": "sim",
                   "zstandard": "sim", "cffi": "sim", "unicorn": "sim", "capstone": "sim",
                   "matplotlib": "plots", "dask": "cluster", "distributed": "cluster"}


def missing_extra(exc: ModuleNotFoundError) -> str | None:
    """The extra whose module ``exc`` did not find (None: not one of the extras')."""
    return EXTRA_OF_MODULE.get((exc.name or "").split(".")[0])


def _hint(command: str, exc: ModuleNotFoundError) -> str:
    extra = missing_extra(exc)
    return (f"mobigrasp {command}: needs mobigrasp[{extra}] (module {exc.name} is missing): "
            f"pip install 'mobigrasp[{extra}]'")


def _unavailable(sub: argparse._SubParsersAction, name: str, exc: ModuleNotFoundError) -> None:
    """``name`` answers with the install hint (its parser, if register() got that far,
    keeps its options)."""
    def run(args: argparse.Namespace) -> int:
        print(_hint(name, exc), file=sys.stderr)
        return 2

    p = sub.choices.get(name)
    if p is None:
        p = sub.add_parser(name, help=f"(needs mobigrasp[{missing_extra(exc)}])",
                           description=_hint(name, exc))
        p.add_argument("rest", nargs=argparse.REMAINDER, help="the command's arguments")
    p.set_defaults(func=run)


def _command_parser(argv: list[str]) -> argparse.ArgumentParser | None:
    """A parser with only the subcommand ``argv`` names, when its module is named after it:
    importing every command (and the benchmarks) costs ~0.5 s of startup, paid by every run
    and by its host process. None when that does not apply (the full parser is used)."""
    if not argv or argv[0].startswith("-"):
        return None
    name = argv[0].replace("-", "_")
    if name.startswith("_") or name not in {m.name for m in
                                             pkgutil.iter_modules(mobigrasp.tools.commands.__path__)}:
        return None
    parser = _Parser(prog="mobigrasp", description=DESCRIPTION)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    importlib.import_module(f"mobigrasp.tools.commands.{name}").register(_Commands(sub))
    return parser if argv[0] in sub.choices else None


def main(argv: list[str] | None = None) -> int:
    """Run ``mobigrasp``; returns the process exit code (2 for bad input, as argparse does)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        parser = _command_parser(argv) or build_parser()
    except ModuleNotFoundError as exc:
        if missing_extra(exc) is None:
            raise
        print(_hint(argv[0] if argv else "", exc), file=sys.stderr)
        return 2
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    setup_logging(getattr(args, "verbose", 0), getattr(args, "quiet", False))
    try:
        return int(args.func(args) or 0)
    except ModuleNotFoundError as exc:
        if missing_extra(exc) is None:
            raise
        print(_hint(args.command, exc), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except OSError as exc:  # a file or port problem the command did not name: bad input
        where = f" {exc.filename}:" if exc.filename else ""
        print(f"mobigrasp {args.command}:{where} {exc.strerror or exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
