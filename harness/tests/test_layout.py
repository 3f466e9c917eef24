"""The layout of the harness (issue 19): no module imports another that imports it back, no
import hides inside a function, and errors.py, which every module may import, imports nothing
of the harness."""
import ast
from pathlib import Path

HARNESS = Path(__file__).resolve().parents[1]


def modules():
    """{dotted name: path} of every module of the harness but its tests."""
    out = {}
    for path in sorted(HARNESS.rglob("*.py")):
        parts = path.relative_to(HARNESS.parent).with_suffix("").parts
        if "tests" in parts:
            continue
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


def imports(name, path, known):
    """The harness modules that the module name (at path) imports, and the lines of imports
    that are not at the top level of the module."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found, nested = set(), []
    top = {id(node) for node in tree.body}
    for node in ast.walk(tree):
        if not isinstance(node, (ast.Import, ast.ImportFrom)):
            continue
        if id(node) not in top:
            nested.append(node.lineno)
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name in known}
            continue
        base = node.module or ""
        if node.level:
            anchor = package.split(".")[:len(package.split(".")) - node.level + 1]
            base = ".".join(anchor + ([base] if base else []))
        for alias in node.names:
            sub = f"{base}.{alias.name}"
            if sub in known:
                found.add(sub)
            elif base in known:
                found.add(base)
    return found - {name}, nested


def graph():
    known = modules()
    return {name: imports(name, path, known) for name, path in known.items()}


def test_no_import_inside_a_function():
    nested = {name: lines for name, (_, lines) in graph().items() if lines}
    assert nested == {}


def test_no_import_cycle():
    edges = {name: found for name, (found, _) in graph().items()}
    state, cycles = {}, []

    def visit(node, path):
        state[node] = "open"
        for nxt in sorted(edges.get(node, ())):
            if state.get(nxt) == "open":
                cycles.append(path[path.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = "done"

    for node in sorted(edges):
        if node not in state:
            visit(node, [node])
    assert cycles == []


def test_errors_imports_nothing_of_the_harness():
    found, _ = graph()["harness.errors"]
    assert found == set()


def test_the_layout_is_read():
    """The checks above see the modules and their ties (a parser that found nothing passes)."""
    edges = {name: found for name, (found, _) in graph().items()}
    assert {"harness.compare", "harness.expressions", "harness.families.piles", "harness.report.plots",
            "harness.runner", "harness.stability"} <= set(edges)
    assert "harness.expressions" in edges["harness.compare"]
    assert "harness.runner" in edges["harness.stability"]
    assert "harness.families" in edges["harness.__main__"]
    assert "harness.errors" in edges["harness.families.piles"]
