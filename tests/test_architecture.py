"""The house rules of the package layout (docs/architecture.md), checked on the source's imports, those
at the top of a module and those inside a function alike: the library never reads the study config, the
hydrocode is the ground floor, and no two modules, nor two packages, import each other, directly or around
a circle."""

from __future__ import annotations

import ast
import functools
import graphlib
import subprocess
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "shockcal"
# the rooms that read the study config: the commands and the study package (the figure catalogue among it)
CONFIG_READERS = ("shockcal.cli", "shockcal.study")


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@functools.cache
def _imports() -> dict[str, set[str]]:
    """Every shockcal module and the shockcal modules it imports (at the top or inside a function)."""
    modules = {_module_name(path): path for path in PACKAGE.rglob("*.py")}
    graph = {}
    for name, path in modules.items():
        found = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("shockcal"):
                found.add(node.module)
                found.update(f"{node.module}.{alias.name}" for alias in node.names
                             if f"{node.module}.{alias.name}" in modules)
            elif isinstance(node, ast.Import):
                found.update(alias.name for alias in node.names if alias.name.startswith("shockcal"))
        graph[name] = {m for m in found if m in modules and m != name}
    return graph


def _is_in(module: str, rooms) -> bool:
    return any(module == room or module.startswith(room + ".") for room in rooms)


def test_no_library_module_reads_the_study_config():
    offenders = {m: sorted(i for i in imported if _is_in(i, ("shockcal.study",)))
                 for m, imported in _imports().items() if not _is_in(m, CONFIG_READERS)}
    assert not {m: i for m, i in offenders.items() if i}, "library modules importing shockcal.study"


def test_the_hydrocode_imports_nothing_of_the_study():
    for module, imported in _imports().items():
        if _is_in(module, ("shockcal.hydro",)):
            ground = ("shockcal.hydro", "shockcal.units", "shockcal.errors", "shockcal.settings_model")
            outside = sorted(i for i in imported if not _is_in(i, ground))
            assert not outside, f"{module} imports {outside}: the hydrocode is the ground floor"


def test_no_import_circles():
    # every module, the package's own __init__ (the lazy notebook API) and the cli's registry included
    graphlib.TopologicalSorter(_imports()).prepare()      # raises CycleError naming the circle


def _room(module: str) -> str:
    """The package a module belongs to (`shockcal.design` for shockcal.design.waves), or the module itself
    for a top-level one (`shockcal.io`)."""
    return ".".join(module.split(".")[:2])


def test_no_import_circles_between_packages():
    # a function-level import hides a circle from module import order, not from the layering: e.g.
    # design -> inference -> emulator -> design
    graph: dict[str, set[str]] = {}
    for module, imported in _imports().items():
        graph.setdefault(_room(module), set()).update({_room(i) for i in imported} - {_room(module)})
    graphlib.TopologicalSorter(graph).prepare()      # raises CycleError naming the circle


def test_a_simulate_job_loads_neither_the_feature_extractor_nor_scipy_stats():
    """The most numerous job of a study pays only for what it runs: what `shockcal simulate` imports (its
    command's imports and the built-in simulator) leaves out scipy.stats (1.7 CPU-s of a job's start,
    measured 2026-11-29) and scikit-learn, which a change of import placement could bring back."""
    tree = ast.parse((PACKAGE / "cli" / "simulate.py").read_text())
    modules = sorted({node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module
                      and node.module.startswith("shockcal")} | {"shockcal.simulators.builtin"})
    code = "; ".join(f"import {m}" for m in modules) + "; import sys; print(' '.join(sorted(sys.modules)))"
    loaded = set(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split())
    assert not loaded & {"scipy.stats", "sklearn", "shockcal.velocimetry.features", "matplotlib"}
