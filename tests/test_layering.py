"""The runtime stays light: planner/ never loads JAX, pyvista or pxr."""

import subprocess
import sys


def test_planner_does_not_import_heavy_packages():
    code = ("import sys, planner, planner._crowd, planner._simulation, planner._presets; "
            "bad = [m for m in sys.modules if m.split('.')[0] in ('jax', 'jaxlib', 'pyvista', 'pxr', 'optimistix')]; "
            "print(bad); sys.exit(1 if bad else 0)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
