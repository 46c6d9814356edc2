"""The runtime stays light: planner/ never loads JAX, pyvista or pxr."""

import subprocess
import sys


def test_planner_does_not_import_heavy_packages():
    code = ("import sys, planner, planner._crowd, planner._simulation, planner._presets; "
            "bad = [m for m in sys.modules if m.split('.')[0] in ('jax', 'jaxlib', 'pyvista', 'pxr', 'optimistix')]; "
            "print(bad); sys.exit(1 if bad else 0)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_tuning_imports_only_the_planners_public_names():
    # The JAX side reads the runtime through its public names only (planner's __all__ and the packed
    # arrays' layout, planner.layout): a private module can change without breaking the tuning.
    import ast
    from pathlib import Path

    import planner
    import planner.layout

    public = {"planner": set(planner.__all__), "planner.layout": set(planner.layout.__all__)}
    private = []
    for path in sorted((Path(__file__).resolve().parent.parent / "tuning").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "planner":
                names = {a.name for a in node.names}
                if node.module not in public or not names <= public[node.module]:
                    private.append(f"{path.name}:{node.lineno}: from {node.module} import {sorted(names)}")
            elif isinstance(node, ast.Import) and any(a.name.startswith("planner.") for a in node.names):
                private.append(f"{path.name}:{node.lineno}: import {[a.name for a in node.names]}")
    assert not private, "\n".join(private)
