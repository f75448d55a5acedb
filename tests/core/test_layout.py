"""The package layout shows the pipeline: each stage one folder, no stage reaching back up.

Stages in order; a module may import from its own stage and the ones before it:
core < mapping < perception, planning, localization < datasets, world < segmenter < systems
< outputs < the top-level entry points (pipeline, run, CLIs) < evaluate. No import cycles (lazy
imports included) and no private name imported from another module.
"""

from __future__ import annotations

import ast
from pathlib import Path

import networkx as nx

ROOT = Path(__file__).resolve().parents[2]
RANK = {
    "core": 0,
    "models": 0,
    "mapping": 1,
    "perception": 2,
    "planning": 2,
    "localization": 2,
    "datasets": 3,
    "world": 3,
    "segmenter": 4,
    "systems": 5,
    "outputs": 6,
    "": 7,  # f2n_drake/*.py: the pipeline and the entry points
    "evaluate": 8,
}


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT)
    parts = list(rel.parts)
    if parts[0] in ("systems", "models"):
        parts.insert(0, "f2n_drake")
    parts[-1] = parts[-1].removesuffix(".py")
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    return {
        _module_name(p): p
        for d in ("f2n_drake", "systems", "models")
        for p in (ROOT / d).rglob("*.py")
    }


def _stage(module: str, modules: dict[str, Path]) -> str:
    parts = module.split(".")
    if len(parts) == 1:
        return ""
    is_package = modules[module].name == "__init__.py"
    return parts[1] if len(parts) > 2 or is_package else ""


def _imports(modules: dict[str, Path]) -> list[tuple[str, str, str]]:
    """(importer, imported module, imported name) for every f2n_drake import, lazy ones too."""
    found = []
    for module, path in modules.items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("f2n_drake"):
                for alias in node.names:
                    full = f"{node.module}.{alias.name}"
                    target = full if full in modules else node.module
                    found.append((module, target, alias.name))
            elif isinstance(node, ast.Import):
                found += [
                    (module, a.name, "") for a in node.names if a.name.startswith("f2n_drake")
                ]
    return found


def test_every_stage_has_a_rank():
    modules = _modules()
    assert {_stage(m, modules) for m in modules} <= set(RANK)


def test_no_stage_imports_a_later_stage():
    modules = _modules()
    upward = [
        f"{a} -> {b}"
        for a, b, _ in _imports(modules)
        if b in modules and RANK[_stage(b, modules)] > RANK[_stage(a, modules)]
    ]
    assert upward == []


def test_no_import_cycles():
    modules = _modules()
    graph = nx.DiGraph((a, b) for a, b, _ in _imports(modules) if b in modules and a != b)
    assert list(nx.simple_cycles(graph)) == []


def test_no_private_names_across_modules():
    private = [f"{a} <- {b}.{n}" for a, b, n in _imports(_modules()) if n.startswith("_")]
    assert private == []
