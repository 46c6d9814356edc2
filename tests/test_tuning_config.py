"""tuning's JAX settings: float64, and compiled programs kept on disk between processes."""

from __future__ import annotations

import json
import os
import subprocess
import sys

# One jitted program, compiled in a fresh process with the cache folder of the test.
PROGRAM = """
import json, jax, jax.numpy as jnp
from footfall.tuning._config import enable_x64
enable_x64()
y = jax.jit(lambda x: jnp.tanh(x) * 3.0 + x ** 2)(jnp.arange(5.0))
print(json.dumps({"dtype": str(y.dtype), "y": [float(v) for v in y],
                  "cache": jax.config.jax_compilation_cache_dir}))
"""


def _run(env_cache, extra=""):
    env = dict(os.environ, FOOTFALL_JAX_CACHE_DIR=str(env_cache))
    proc = subprocess.run([sys.executable, "-c", extra + PROGRAM], capture_output=True, text=True, timeout=120,
                          env=env, cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_a_second_process_reuses_the_first_ones_compiled_program(tmp_path):
    cache = tmp_path / "jax"
    first = _run(cache)
    assert first["dtype"] == "float64" and first["cache"] == str(cache)
    entries = sorted(p.name for p in cache.iterdir())
    assert entries  # the program was written, however quick its compilation
    second = _run(cache)
    assert second == first
    assert sorted(p.name for p in cache.iterdir()) == entries  # read back, not compiled and written again


def test_a_cache_folder_the_user_chose_is_kept(tmp_path):
    mine = tmp_path / "mine"
    out = _run(tmp_path / "ours", extra=f"import jax; jax.config.update('jax_compilation_cache_dir', {str(mine)!r})\n")
    assert out["cache"] == str(mine) and not (tmp_path / "ours").exists()
