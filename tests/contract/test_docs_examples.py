"""The Python examples in README.md and docs/ import what they say: every module and name an
example imports exists in the installed package (a reader copies them as they are)."""

import ast
import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BLOCK = re.compile(r"```python\n(.*?)```", re.S)


def _examples() -> list[tuple[str, str]]:
    found = []
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for k, match in enumerate(BLOCK.finditer(path.read_text(encoding="utf-8"))):
            found.append((f"{path.name}#{k}", match.group(1)))
    return found


EXAMPLES = _examples()


def _imports(source: str) -> list[tuple[str, str | None]]:
    """(module, name) of every import in ``source``; name None for ``import module``."""
    out: list[tuple[str, str | None]] = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out += [(node.module, alias.name) for alias in node.names]
        elif isinstance(node, ast.Import):
            out += [(alias.name, None) for alias in node.names]
    return out


def test_the_docs_have_python_examples():
    assert sum(1 for _, src in EXAMPLES if "import" in src) >= 2


@pytest.mark.parametrize("where, source", EXAMPLES, ids=[w for w, _ in EXAMPLES])
def test_example_imports_resolve(where, source):
    try:
        imports = _imports(source)
    except SyntaxError:
        pytest.skip(f"{where} is a fragment, not a program")
    for module, name in imports:
        if module.split(".")[0] in {"serial", "cv2", "numpy", "pytest", "time", "os", "sys"}:
            continue
        mod = importlib.import_module(module)
        if name is not None and name != "*":
            assert hasattr(mod, name) or importlib.util.find_spec(f"{module}.{name}"), (
                f"{where}: {module} has no {name}")
