"""Shared test helpers."""

import os
import signal
import time

import pytest

# pytest-xdist runs a worker per core (and one more): a numba thread pool per worker on top would oversubscribe the
# cores (parallel kernels spin at their barriers). Set before any test module imports numba.
if os.environ.get("PYTEST_XDIST_WORKER"):
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")

from footfall import configure_numba_cache  # noqa: E402

configure_numba_cache()  # before any test module imports the planner's kernels (the CLI's main does the same)


@pytest.fixture
def kill_a_busy_worker():
    """``make(client) -> (progress, killed)``: a ``progress(task, done)`` callback that, the first time it
    is called, waits (bounded) until some worker of ``client`` is running a task and SIGKILLs that
    worker's process; ``killed`` lists the workers it killed (one at most)."""

    def make(client):
        killed = []

        def progress(task, done):
            if killed:
                return
            for _ in range(200):
                busy = [w for w, keys in client.processing().items() if keys]
                if busy:
                    pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
                    os.kill(pid, signal.SIGKILL)
                    killed.append(busy[0])
                    return
                time.sleep(0.05)

        return progress, killed

    return make


# --------------------------------------------------------------------------- seeds
# Property tests run their fixed seeds (every seed that ever failed joins its test's fixed list)
# plus fresh ones drawn for this session, so that passing means generalising. The session's draw is
# printed in the header; FOOTFALL_TEST_SEED=<n> replays it. Failure messages name the seed.
# Drawn once, by the first process that imports this file: pytest-xdist's workers inherit it through
# the environment, so that every worker collects the same parametrised seeds.
_SESSION_SEED = int(os.environ.setdefault("FOOTFALL_TEST_SEED", str(int.from_bytes(os.urandom(4), "little"))))


@pytest.hookimpl(optionalhook=True)  # optional: a run with -p no:xdist has no such hook
def pytest_xdist_auto_num_workers(config):
    """``-n auto``: one worker more than the cores (at most --maxprocesses). Many tests wait on
    processes of their own (the CLI, renderers, Dask workers, a headless browser): on 2 cores, 3
    workers ran the suite in 4:37 where 2 took 5:01, back to back on the same machine."""
    return (os.cpu_count() or 1) + 1


def pytest_report_header(config):
    return f"footfall fresh seeds: FOOTFALL_TEST_SEED={_SESSION_SEED} (set it to replay this session's draw)"


# --------------------------------------------------------------------------- one compile of the kernels
@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session):
    """The planner's kernels compiled once, before the workers start (tests/warm_up.py says why)."""
    from warm_up import compile_kernels

    if os.environ.get("PYTEST_XDIST_WORKER") or session.config.getoption("collectonly", False):
        return
    started = time.perf_counter()
    for line in compile_kernels():
        print(f"footfall: a warm-up process failed ({line})")
    if time.perf_counter() - started > 10:
        print(f"footfall: compiled the numba kernels once ({time.perf_counter() - started:.0f} s)")


def fresh_seeds(fixed, n_fresh, *, salt=0):
    """``fixed`` seeds followed by ``n_fresh`` seeds drawn for this session (in [1000, 2**31))."""
    import numpy as np

    rng = np.random.default_rng([_SESSION_SEED, salt])
    return list(fixed) + [int(s) for s in rng.integers(1000, 2**31 - 1, n_fresh)]


# --------------------------------------------------------------------------- the command line in-process
def footfall_cli(*args, cwd=None):
    """Run ``footfall ARGS`` in this process, as the console script does (:func:`footfall.cli.main`):
    a ``subprocess.CompletedProcess`` with its exit code and everything it printed.

    For the many bad-input cases: a Python process per case cost about a second of imports each
    (a fifth of the suite went to starting interpreters). What a process adds is kept: an exception
    that escapes ``main`` fails the test (a process would print its traceback), and warnings print
    on the captured stderr, as they would in a process. A few tests still start real processes
    (the entry point itself, import-time behaviour).
    """
    import contextlib
    import io
    import subprocess
    import warnings

    from footfall.cli import main

    argv = [str(a) for a in args]
    out, err = io.StringIO(), io.StringIO()
    code = 0
    here = os.getcwd()
    try:
        if cwd is not None:
            os.chdir(cwd)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), warnings.catch_warnings():
            warnings.simplefilter("default")
            warnings.showwarning = (lambda message, category, filename, lineno, file=None, line=None:
                                    err.write(warnings.formatwarning(message, category, filename, lineno, line)))
            try:
                main(argv)
            except SystemExit as e:
                if isinstance(e.code, str):  # sys.exit("message"): the interpreter prints it, exit code 1
                    err.write(e.code + "\n")
                code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    finally:
        os.chdir(here)
    return subprocess.CompletedProcess(["footfall", *argv], code, out.getvalue(), err.getvalue())


# --------------------------------------------------------------------------- one main job per session
@pytest.fixture(scope="session")
def main_job(tmp_path_factory):
    """``(out, summary)`` of one ``footfall run --quick --workers 1 --out OUT --json``, once per test session.

    The main job's tune and report are the suite's two longest pieces of work; its report is the quick
    sweep with the recording's renders, which the report's tests read rather than sweep again. With
    xdist the first worker to ask runs it and the others wait for it: a file lock in the folder the
    workers share. In one process (``--workers 1``): the suite keeps both cores busy on its own, and
    the job's four local worker processes cost 21 s of CPU to start (69 -> 47 core-seconds for the job,
    2026-11-26); the sweep and the tune on local workers are tests of their own (test_distributed*)."""
    import fcntl
    import json
    import subprocess
    import sys

    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent  # the session's folder, shared by its workers
    out = root / "main-job"
    result = root / "main-job.result.json"
    with open(root / "main-job.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not result.exists():
            env = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
            argv = ["run", "--quick", "--workers", "1", "--out", str(out), "--json"]
            proc = subprocess.run([sys.executable, "-m", "footfall.cli", *argv], capture_output=True, text=True,
                                  timeout=900, env=env)
            result.write_text(json.dumps({"returncode": proc.returncode, "stdout": proc.stdout,
                                          "stderr": proc.stderr[-4000:]}))
    done = json.loads(result.read_text())
    assert done["returncode"] == 0, done["stderr"]
    return out, json.loads(done["stdout"])
