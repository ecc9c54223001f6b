"""No import circle between the package's modules: every import that runs, also one inside a
function, is an arrow of grimp's graph (the graph import-linter checks), and no module may reach
itself. An import under ``if TYPE_CHECKING:`` names a type for the annotations and never runs,
so it draws no arrow here.

The graph is built from the installed package's folders (docs/architecture.md, "Seeing the
arrows"), so the editable install's tree of links or a wheel's tree."""

import grimp


def _circles(graph) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    modules = sorted(m for m in graph.modules if m.split(".")[0] == "mobigrasp")
    arrows = {m: sorted(x for x in graph.find_modules_directly_imported_by(m)
                        if x.split(".")[0] == "mobigrasp") for m in modules}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in modules:
        if root in index:
            continue
        work = [(root, 0)]
        while work:
            v, i = work.pop()
            if i == 0:
                index[v] = low[v] = len(index)
                stack.append(v)
                on_stack.add(v)
            if i < len(arrows[v]):
                work.append((v, i + 1))
                w = arrows[v][i]
                if w not in index:
                    work.append((w, 0))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    found.append(sorted(comp))
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[v])
    return found


def test_the_finder_sees_a_circle():
    class Graph:
        modules = {"mobigrasp.a", "mobigrasp.b", "mobigrasp.c", "mobigrasp.d"}

        @staticmethod
        def find_modules_directly_imported_by(m):
            return {"mobigrasp.a": {"mobigrasp.b"}, "mobigrasp.b": {"mobigrasp.c"},
                    "mobigrasp.c": {"mobigrasp.a", "mobigrasp.d"}, "mobigrasp.d": set()}[m]

    assert _circles(Graph) == [["mobigrasp.a", "mobigrasp.b", "mobigrasp.c"]]


def test_no_import_circle_between_modules():
    graph = grimp.build_graph("mobigrasp", exclude_type_checking_imports=True, cache_dir=None)
    assert len(graph.modules) > 200  # the whole package, not a shadowing folder
    circles = _circles(graph)
    assert not circles, "import circles:\n" + "\n".join(" <-> ".join(c) for c in circles)
