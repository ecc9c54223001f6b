"""Rules import-linter cannot express: protocol/ is standard library only, and no wall clock.

The protocol must port to the ATmega128 (docs/protocol.md) and host/protocol/firmware get time
from a Clock (docs/cosim.md).
"""

import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _imports(path: Path) -> list[tuple[int, str]]:
    tree = ast.parse(path.read_text(), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.append((node.lineno, node.module))
    return found


def test_protocol_imports_only_stdlib():
    bad = []
    for path in sorted((ROOT / "protocol").rglob("*.py")):
        for line, name in _imports(path):
            top = name.split(".")[0]
            own = name == "mobigrasp.protocol" or name.startswith("mobigrasp.protocol.")
            if not own and top not in sys.stdlib_module_names and top != "__future__":
                bad.append(f"{path.relative_to(ROOT)}:{line} imports {name}")
    assert not bad, "protocol/ must import only the standard library:\n" + "\n".join(bad)


WALL_CLOCK = {("time", "time"), ("time", "sleep"), ("time", "monotonic"), ("time", "perf_counter"),
              ("time", "time_ns"), ("time", "monotonic_ns"), ("datetime", "now")}


def test_no_wall_clock_in_host_protocol_firmware():
    bad = []
    for sub in ("host", "protocol", "mcu_sim/firmware"):
        for path in sorted((ROOT / sub).rglob("*.py")):
            tree = ast.parse(path.read_text(), filename=str(path))
            for node in ast.walk(tree):
                if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
                    if (node.value.id, node.attr) in WALL_CLOCK:
                        rel = path.relative_to(ROOT)
                        bad.append(f"{rel}:{node.lineno} {node.value.id}.{node.attr}")
                if isinstance(node, ast.ImportFrom) and node.module == "time":
                    names = {a.name for a in node.names}
                    if names & {"time", "sleep", "monotonic", "perf_counter"}:
                        rel = path.relative_to(ROOT)
                        bad.append(f"{rel}:{node.lineno} from time import {names}")
    assert not bad, "wall clock used where the simulated Clock belongs:\n" + "\n".join(bad)


def test_host_does_not_import_simulator():
    bad = []
    for path in sorted((ROOT / "host").rglob("*.py")):
        for line, name in _imports(path):
            parts = name.split(".")
            inside = parts[1] if parts[0] == "mobigrasp" and len(parts) > 1 else None
            if parts[0] == "pymunk" or inside in {"mcu_sim", "tools"}:
                bad.append(f"{path.relative_to(ROOT)}:{line} imports {name}")
    assert not bad, "\n".join(bad)
