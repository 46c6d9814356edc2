"""Where numba caches the kernels (issue 17: configured at the entry points, not on import)."""

import os
import subprocess
import sys

CLEAN = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "FOOTFALL_NUMBA_CACHE_ROOT")}


def _run(code: str, env: dict) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)


def test_importing_the_planner_changes_no_environment_variable():
    code = ("import os; before = dict(os.environ); import footfall.planner, footfall.planner._crowd; "
            "changed = sorted(k for k in set(before) | set(os.environ) if before.get(k) != os.environ.get(k)); "
            "print(changed); assert not [k for k in changed if k.startswith(('NUMBA', 'FOOTFALL'))], changed")
    proc = _run(code, dict(CLEAN, OMP_WAIT_POLICY="PASSIVE"))
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_the_cache_folder_is_named_by_the_kernels_and_found_again_by_a_child(tmp_path):
    code = ("import os, subprocess, sys; from footfall import configure_numba_cache; "
            "first = configure_numba_cache(); assert configure_numba_cache() == first; "
            "child = subprocess.run([sys.executable, '-c', 'from footfall import configure_numba_cache as c; print(c())'], "
            "capture_output=True, text=True, check=True).stdout.strip(); "
            "print(first, child, os.environ['NUMBA_CACHE_DIR'])")
    proc = _run(code, dict(CLEAN, NUMBA_CACHE_DIR=str(tmp_path)))
    assert proc.returncode == 0, proc.stderr
    first, child, env = proc.stdout.split()
    assert first == child == env  # the same folder, not one nested inside it
    assert os.path.dirname(first) == str(tmp_path) and len(os.path.basename(first)) == 16


def test_the_command_line_configures_it_before_its_commands_run(tmp_path):
    code = ("import os, numba.core.config as c; from footfall.cli import main\n"
            "try:\n    main(['scenarios'])\nexcept SystemExit as e:\n    assert not e.code, e.code\n"
            "print(os.environ['NUMBA_CACHE_DIR'], c.CACHE_DIR)")
    proc = _run(code, dict(CLEAN, NUMBA_CACHE_DIR=str(tmp_path)))
    assert proc.returncode == 0, proc.stderr[-2000:]
    env, config = proc.stdout.split()[-2:]
    assert env == config and os.path.dirname(env) == str(tmp_path)


def test_configuring_after_the_planner_was_imported_warns(tmp_path):
    code = ("import warnings, footfall.planner; from footfall import configure_numba_cache\n"
            "with warnings.catch_warnings(record=True) as w:\n    warnings.simplefilter('always')\n"
            "    configure_numba_cache(); configure_numba_cache()\n"
            "print(len(w), w[0].message if w else '')")
    proc = _run(code, dict(CLEAN, NUMBA_CACHE_DIR=str(tmp_path)))
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("1 configure_numba_cache: footfall.planner was imported before")


def test_importing_the_planner_with_a_cache_folder_set_by_hand_warns(tmp_path):
    # numba reuses a kernel cached there while the kernel's own file is unchanged, with the code its callees
    # in other files had then: a script that imported the planner first counted 38 leg crossings where the
    # command line counted 2. The folder configure_numba_cache names after the sources is quiet.
    code = "import footfall.planner"
    foreign = _run(code, dict(CLEAN, NUMBA_CACHE_DIR=str(tmp_path), PYTHONWARNINGS="error::RuntimeWarning"))
    assert foreign.returncode != 0
    assert "NUMBA_CACHE_DIR=" in foreign.stderr and "configure_numba_cache()" in foreign.stderr
    named = _run("from footfall import configure_numba_cache; configure_numba_cache(); " + code,
                 dict(CLEAN, NUMBA_CACHE_DIR=str(tmp_path), PYTHONWARNINGS="error::RuntimeWarning"))
    assert named.returncode == 0, named.stderr[-2000:]
    default = _run(code, dict(CLEAN, PYTHONWARNINGS="error::RuntimeWarning"))  # numba's own default: quiet
    assert default.returncode == 0, default.stderr[-2000:]
