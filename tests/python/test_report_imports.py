"""The report package imports no module of itself in a circle. Every `from . import x`
and `from .x import y` in scripts/stepbench_report, at the top of a module or inside a
function (a deferred import still closes a circle), is an edge; the graph must be
acyclic. No study file is needed: the sources are read with `ast`, not imported."""
import ast
import pathlib

PACKAGE = pathlib.Path(__file__).resolve().parents[2] / "scripts" / "stepbench_report"


def package_imports(path, modules):
    """The package's modules that `path` imports (relative imports only: the package
    is never imported by its absolute name from inside)."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if not isinstance(node, ast.ImportFrom) or node.level != 1:
            continue
        if node.module:  # from .x import y
            out.add(node.module.split(".")[0])
        else:  # from . import x, y
            out.update(alias.name for alias in node.names)
    return out & modules


def import_graph():
    files = {p.stem: p for p in PACKAGE.glob("*.py")}
    modules = set(files)
    return {m: package_imports(p, modules) for m, p in files.items()}


def find_cycle(graph):
    """One cycle as a list of modules (first == last), or None: a depth-first walk that
    meets a module already on its path."""
    done = set()

    def visit(m, path):
        if m in path:
            return path[path.index(m):] + [m]
        if m in done:
            return None
        for n in sorted(graph[m]):
            found = visit(n, path + [m])
            if found:
                return found
        done.add(m)
        return None

    for m in sorted(graph):
        found = visit(m, [])
        if found:
            return found
    return None


def test_the_graph_is_read():
    g = import_graph()
    # The edges the report is built on, so that a parser that found nothing cannot pass.
    assert {"study", "formatting"} <= g["tables"], g["tables"]
    assert {"figures", "tables", "loop"} <= g["report"], g["report"]


def test_no_import_circle():
    cycle = find_cycle(import_graph())
    assert cycle is None, "import circle in scripts/stepbench_report: " + " -> ".join(cycle)


def test_a_circle_is_found():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) is not None
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set()}) is None
