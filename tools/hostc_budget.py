"""The ARM920T build of hostc/ (``make hostc``): the worst-case stack of each external function.

``python -m mobigrasp.tools.hostc_budget DIR`` reads the ``.ci`` files that ``-fcallgraph-info=su``
wrote beside the objects in DIR: every function's frame (the ``-fstack-usage`` figure) and its
direct calls, across all the objects. Each external function (a kernel, a task's step, the
program's entry) is a possible entry point; its worst case is its frame plus the deepest chain
of callees (tools/firmware_budget.py ``worst_stack``). A libgcc routine (division, soft-float)
has no ``.ci`` node: it is charged ``LIBGCC_CHAIN_BYTES``, the deepest libgcc chain in the ELF
of ``make hostc-arm`` (__aeabi_ldivmod 16 bytes into __udivmoddi4 32); any other function
without a node is charged the same, so the board's objects (hostc/arm/) belong in DIR too. A
call through a function pointer cannot be followed: the functions that reach one are marked,
and their figure covers the direct calls only. A frame gcc calls dynamic (a variable-length
array) is marked too.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from mobigrasp.tools.firmware_budget import BudgetError, worst_stack

LIBGCC_CHAIN_BYTES = 48
INDIRECT = "__indirect_call"

_NODE = re.compile(r'^node: \{ title: "([^"]+)" label: "([^"\\]+)\\n[^"]*?(?:\\n(\d+) bytes '
                   r'\(([^)]+)\))?"')
_EDGE = re.compile(r'^edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')


def read_callgraph(build: Path) -> tuple[dict[str, int], dict[str, set[str]], dict[str, str],
                                         set[str]]:
    """(frame bytes, callees, printed name, functions with a dynamic frame) of every function
    in the ``.ci`` files below ``build``."""
    frame: dict[str, int] = {}
    graph: dict[str, set[str]] = {}
    name: dict[str, str] = {}
    dynamic: set[str] = set()
    files = sorted(build.rglob("*.ci"))
    if not files:
        raise BudgetError(f"{build}: no .ci files (build with -fcallgraph-info=su)")
    for ci in files:
        for line in ci.read_text().splitlines():
            node = _NODE.match(line)
            if node and node.group(3) is not None:
                title = node.group(1)
                frame[title] = int(node.group(3))
                name[title] = node.group(2)
                if node.group(4) != "static":
                    dynamic.add(title)
                graph.setdefault(title, set())
                continue
            edge = _EDGE.match(line)
            if edge and edge.group(1) != edge.group(2):
                graph.setdefault(edge.group(1), set()).add(edge.group(2))
    return frame, graph, name, dynamic


def entry_stacks(build: Path) -> list[tuple[str, int, list[str], bool]]:
    """(function, worst-case stack bytes, its deepest chain, makes an indirect call) of each
    external function of the build (a static one's title is ``file:name``), the deepest
    first."""
    frame, graph, name, dynamic = read_callgraph(build)
    direct = {f: {c for c in cs if c != INDIRECT} for f, cs in graph.items()}
    memo: dict[str, int] = {}
    rows = []
    for fn in frame:
        if ":" in fn:
            continue
        total = worst_stack(fn, direct, frame, memo, library_bytes=LIBGCC_CHAIN_BYTES)
        chain, at = [fn], fn
        while direct.get(at):
            at = max(sorted(direct[at]), key=memo.__getitem__)
            chain.append(at)
        indirect = any(INDIRECT in graph.get(f, ()) for f in _reachable(fn, direct))
        rows.append((name[fn], total, [name.get(f, f) + ("*" if f in dynamic else "")
                                       for f in chain], indirect))
    rows.sort(key=lambda r: (-r[1], r[0]))
    return rows


def _reachable(fn: str, graph: dict[str, set[str]]) -> set[str]:
    seen, todo = {fn}, [fn]
    while todo:
        for c in graph.get(todo.pop(), ()):
            if c not in seen:
                seen.add(c)
                todo.append(c)
    return seen


def main(argv: list[str] | None = None) -> int:
    """Print each external function's worst-case stack and its deepest chain."""
    ap = argparse.ArgumentParser(prog="hostc_budget", description=__doc__.split("\n")[0])
    ap.add_argument("build", type=Path, help="the folder of the objects and their .ci files")
    args = ap.parse_args(argv)
    try:
        rows = entry_stacks(args.build)
    except (BudgetError, OSError) as exc:
        print(f"hostc_budget: {exc}", file=sys.stderr)
        return 2
    print(f"worst-case stack per external function (bytes; a libgcc call {LIBGCC_CHAIN_BYTES}; "
          "+: also calls through a pointer, not counted; *: dynamic frame)")
    for fn, total, chain, indirect in rows:
        print(f"{total:7d}{'+' if indirect else ' '} {fn:32s} {' > '.join(chain[1:])}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
