"""The package's shape holds: no module over 600 lines, no import cycle between its modules (imports inside
functions count too: a lazy import hides a cycle from Python, not from a reader), and nothing outside a
family's folder names a family's types (analysis, plotting, the registry's users)."""

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "splinevis"
MAX_LINES = 600


def _modules():
    for path in sorted(PKG.rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        yield name, path


def _imports(name, path):
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            yield target
            for alias in node.names:  # "from . import schemes" imports a module
                yield f"{target}.{alias.name}"
        elif isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name


def _graph():
    mods = dict(_modules())
    graph = {m: set() for m in mods}
    for m, path in mods.items():
        for target in _imports(m, path):
            if target in mods and target != m:
                graph[m].add(target)
    return graph


def _cycles(graph):
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    return out


def _package_inits(graph):
    # a package's __init__ re-exports its submodules: edges from a submodule to its own package (or an
    # ancestor) are how relative imports of siblings read, not a dependency of the package on itself
    return {m: {t for t in ts if not m.startswith(t + ".")} for m, ts in graph.items()}


def test_no_module_is_over_600_lines():
    long = [(str(p.relative_to(ROOT)), n) for _, p in _modules() if (n := len(p.read_text().splitlines())) > MAX_LINES]
    assert long == [], f"split these modules along their ideas: {long}"


def test_no_import_cycle():
    assert _cycles(_package_inits(_graph())) == []


FAMILY_TYPES = r"\b(QuarticTrianglePatch|TerrainSpline|VolumeSpline|Isosurface|HeightGrid|VolumeGrid)\b"


@pytest.mark.parametrize("place", ["splinevis/analysis", "splinevis/plotting.py", "splinevis/programs.py",
                                   "splinevis/selftest.py", "splinevis/gl"])
def test_no_family_types_outside_family_folders(place):
    paths = [ROOT / place] if place.endswith(".py") else sorted((ROOT / place).rglob("*.py"))
    hits = []
    for path in paths:
        for k, line in enumerate(path.read_text().splitlines(), 1):
            code = line.split("#", 1)[0]
            if "isinstance" in code and re.search(FAMILY_TYPES, code) or re.search(r"^\s*from \.\.?(analytic|terrain|volume)\b", code):
                hits.append(f"{path.relative_to(ROOT)}:{k}: {line.strip()}")
    assert hits == []
