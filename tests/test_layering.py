"""The house's floors (issue 17): one namespace, footfall.*; a ground floor that imports nothing else
of the project; each package imports only the floors below it (never the CLI); the runtime stays light
(planner never loads JAX, pyvista or pxr); the tuning reads the runtime through its public names."""

import ast
import subprocess
import sys
from importlib import metadata
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# Each repository folder, the package it is installed as, and its floor: a package may import its own
# floor and the ones below, never one above (no two folders import each other).
FLOORS = {
    "footfall": ("footfall", 0),  # the ground floor: errors, atomic writes, task distribution, version
    "planner": ("footfall.planner", 1),
    "scenarios": ("footfall.scenarios", 2),
    "tuning": ("footfall.tuning", 3),
    "benchmarks": ("footfall.benchmarks", 4),
    "reports": ("footfall.reports", 5),
    "cli": ("footfall.cli", 6),
}
OLD_TOP_LEVEL = ("planner", "scenarios", "tuning", "reports", "benchmarks", "cli")


def _package_of(module: str) -> str | None:
    """The folder whose package ``module`` belongs to (the longest matching package name), or None."""
    best = None
    for folder, (package, _) in FLOORS.items():
        if module == package or module.startswith(package + "."):
            if best is None or len(package) > len(FLOORS[best][0]):
                best = folder
    return best


def _imports(path: Path):
    """Every module an ``import`` or ``from ... import`` names in the file (at any depth), with its line."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            yield node.lineno, node.module
            for alias in node.names:  # `from footfall import planner` imports the package footfall.planner
                yield node.lineno, f"{node.module}.{alias.name}"
        elif isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name


def _wrong_imports(path: Path, floor: int) -> list[tuple[int, str, str]]:
    """(line, module, why) of each import in ``path`` that a package on ``floor`` may not make: a
    top-level name of the old layout, or a package on a higher floor."""
    wrong = []
    for line, module in _imports(path):
        if module.split(".")[0] in OLD_TOP_LEVEL:
            wrong.append((line, module, f"a top-level name; footfall.{module}"))
            continue
        target = _package_of(module)  # None: a third-party package
        if target is not None and FLOORS[target][1] > floor:
            wrong.append((line, module, f"floor {FLOORS[target][1]} above {floor}"))
    return wrong


def test_each_package_imports_only_its_floor_and_the_ones_below():
    wrong = [f"{folder}/{path.name}:{line}: imports {module} ({why})"
             for folder, (_, floor) in FLOORS.items()
             for path in sorted((ROOT / folder).glob("*.py"))
             for line, module, why in _wrong_imports(path, floor)]
    assert not wrong, "\n".join(wrong)


def test_the_floor_rule_sees_an_upward_import(tmp_path):
    # The rule above, on two hand-written files: it must flag the planner importing the CLI and a
    # top-level name, and pass the planner importing the ground floor.
    bad = tmp_path / "bad.py"
    bad.write_text("from footfall.cli import app\nimport planner._crowd as c\nfrom footfall import reports\n")
    good = tmp_path / "good.py"
    good.write_text("from footfall._errors import InputError\nfrom footfall.planner import layout\nimport numpy\n")
    floor = FLOORS["planner"][1]
    assert [m for _, m, _ in _wrong_imports(bad, floor)] == ["footfall.cli", "footfall.cli.app", "planner._crowd",
                                                             "footfall.reports"]
    assert _wrong_imports(good, floor) == []


def test_only_the_namespace_is_importable_outside_the_repository(tmp_path):
    # One process for the six names (each a process of its own cost 1-2 s of imports apiece).
    code = ("import importlib, importlib.util\n"
            f"for name in {OLD_TOP_LEVEL!r}:\n"
            "    assert importlib.util.find_spec(name) is None, f'top-level {name} importable'\n"
            "    importlib.import_module(f'footfall.{name}')\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr


def test_the_distribution_installs_one_top_level_name():
    top_level = metadata.distribution("footfall").read_text("top_level.txt")
    assert top_level is not None and top_level.split() == ["footfall"]


def test_planner_does_not_import_heavy_packages():
    code = ("import sys, footfall.planner, footfall.planner._crowd, footfall.planner._simulation, "
            "footfall.planner._presets; "
            "bad = [m for m in sys.modules if m.split('.')[0] in ('jax', 'jaxlib', 'pyvista', 'pxr', 'optimistix')]; "
            "print(bad); sys.exit(1 if bad else 0)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_tuning_imports_only_the_planners_public_names():
    # The JAX side reads the runtime through its public names only (planner's __all__ and the packed
    # arrays' layout, footfall.planner.layout): a private module can change without breaking the tuning.
    from footfall import planner
    from footfall.planner import layout

    public = {"footfall.planner": set(planner.__all__), "footfall.planner.layout": set(layout.__all__)}
    private = []
    for path in sorted((ROOT / "tuning").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and _package_of(node.module or "") == "planner":
                names = {a.name for a in node.names}
                if node.module not in public or not names <= public[node.module]:
                    private.append(f"{path.name}:{node.lineno}: from {node.module} import {sorted(names)}")
            elif isinstance(node, ast.Import) and any(_package_of(a.name) == "planner" for a in node.names):
                private.append(f"{path.name}:{node.lineno}: import {[a.name for a in node.names]}")
    assert not private, "\n".join(private)
