"""The package's layers: imports point one way, no cycles, no module too long, and importing the
package loads neither Taichi nor Dask."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "taichi_sls"
# a layer may import the layers before it, never those after it
ORDER = ["config", "physics", "solver", "io", "jobs", "studies", "cli"]
# layers that may not import each other although one comes later (siblings)
FORBIDDEN = {"io": {"physics", "solver"}, "physics": {"config"}}


def _layer(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "top"


def _imports() -> dict[str, set[str]]:
    """Module -> the taichi_sls modules it imports (absolute names)."""
    graph: dict[str, set[str]] = {}
    for path in PKG.rglob("*.py"):
        rel = path.relative_to(PKG.parent).with_suffix("")
        name = ".".join(rel.parts).removesuffix(".__init__")
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        deps = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")
                    base = base[: len(base) - node.level + 1]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                if target.startswith("taichi_sls"):
                    deps.add(target)
                    deps.update(f"{target}.{a.name}" for a in node.names)
            elif isinstance(node, ast.Import):
                deps.update(a.name for a in node.names if a.name.startswith("taichi_sls"))
        graph[name] = deps
    # keep only names that are modules of the package
    return {m: {d for d in ds if d in graph and d != m} for m, ds in graph.items()}


def test_layers_import_only_the_layers_before_them():
    rank = {layer: i for i, layer in enumerate(ORDER)}
    bad = []
    for mod, deps in _imports().items():
        src = _layer(mod)
        if src not in rank:
            continue
        for d in deps:
            dst = _layer(d)
            if dst not in rank:
                continue
            if rank[dst] > rank[src] or dst in FORBIDDEN.get(src, set()):
                bad.append(f"{mod} -> {d}")
    assert not bad, "imports against the layer order:\n" + "\n".join(sorted(bad))


def test_no_import_cycles():
    graph = _imports()
    # modules importing their own package's __init__ are not a cycle of code
    state: dict[str, int] = {}
    cycles = []

    def visit(m: str, stack: list[str]) -> None:
        state[m] = 1
        for d in graph[m]:
            if m.startswith(d + "."):
                continue
            if state.get(d) == 1:
                cycles.append(" -> ".join(stack[stack.index(d) :] + [d]))
            elif d not in state:
                visit(d, stack + [d])
        state[m] = 2

    for m in graph:
        if m not in state:
            visit(m, [m])
    assert not cycles, "import cycles:\n" + "\n".join(cycles)


def test_no_module_is_too_long():
    long = {
        str(p.relative_to(PKG)): n
        for p in PKG.rglob("*.py")
        if (n := len(p.read_text().splitlines())) > 420
    }
    assert not long, f"modules over 420 lines: {long}"


@pytest.mark.parametrize("heavy", ["taichi", "dask", "distributed", "matplotlib"])
def test_importing_the_package_loads_no_heavy_dependency(heavy):
    code = (
        "import sys, taichi_sls; assert taichi_sls.load_case; "
        f"sys.exit(1 if {heavy!r} in sys.modules else 0)"
    )
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0
