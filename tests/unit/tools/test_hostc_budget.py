"""tools/hostc_budget.py: the worst-case stack per external function from gcc's call graphs."""

import shutil
import subprocess

import pytest

from mobigrasp.tools import hostc_budget
from mobigrasp.tools.firmware_budget import BudgetError

pytestmark = pytest.mark.skipif(shutil.which("arm-none-eabi-gcc") is None,
                                reason="arm-none-eabi-gcc is needed (make arm-tools)")

A = """
int leaf(int *p);
int (*hook)(int);
static int mid(int x)
{ volatile int buf[40]; buf[x & 31] = x; return leaf((int *)buf) + x / buf[2]; }
int top(int x) { volatile int buf[10]; buf[x & 7] = x; return mid(buf[3]) + mid(x + 1); }
int via_pointer(int x) { return hook(x) + 1; }
"""
B = """
int leaf(int *p) { volatile int buf[4]; buf[p[0] & 3] = 1; return buf[1]; }
"""


def _build(tmp_path, sources):
    for name, text in sources.items():
        src = tmp_path / f"{name}.c"
        src.write_text(text)
        subprocess.run(["arm-none-eabi-gcc", "-mcpu=arm920t", "-marm", "-O2", "-c",
                        "-fno-inline", "-fstack-usage", "-fcallgraph-info=su",
                        "-o", str(tmp_path / f"{name}.o"), str(src)], check=True)
    return tmp_path


def _su(tmp_path):
    out = {}
    for su in tmp_path.glob("*.su"):
        for line in su.read_text().splitlines():
            where, size, _ = line.split("\t")
            out[where.rsplit(":", 1)[-1]] = int(size)
    return out


def test_chain_across_objects_with_library_call(tmp_path):
    build = _build(tmp_path, {"a": A, "b": B})
    su = _su(build)
    rows = {fn: (total, chain, indirect)
            for fn, total, chain, indirect in hostc_budget.entry_stacks(build)}
    assert "mid" not in rows  # static: reached through top only
    total, chain, indirect = rows["top"]
    # top > mid > (leaf or the division helper, whichever is deeper)
    deepest = max(su["leaf"], hostc_budget.LIBGCC_CHAIN_BYTES)
    assert total == su["top"] + su["mid"] + deepest
    assert chain[:2] == ["top", "mid"]
    assert not indirect
    assert rows["leaf"] == (su["leaf"], ["leaf"], False)
    assert rows["via_pointer"][2]  # calls through a pointer: flagged


def test_recursion_and_missing_graph_are_errors(tmp_path, capsys):
    build = _build(tmp_path, {"r": "int f(int x) { return x > 0 ? f(x - 1) * 3 + 1 : 0; }\n"
                                   "int g(int x);\nint h(int x) { return g(x) + 1; }\n"
                                   "int g(int x) { return x ? h(x - 1) : 0; }\n"})
    with pytest.raises(BudgetError, match="recursion"):
        hostc_budget.entry_stacks(build)
    assert hostc_budget.main([str(tmp_path / "nothing")]) == 2
    assert "no .ci files" in capsys.readouterr().err
