"""One compile of the planner's numba kernels, before the tests start (``conftest.pytest_sessionstart``),
or while CI installs the system packages (``.ci/run``): ``python tests/warm_up.py``.

On a cold numba cache (a fresh clone) the crowd runtime's kernels take about a minute of one core
to compile, and every process that meets them cold compiles them itself: both xdist workers at once,
and every CLI subprocess a test starts meanwhile (on 2 cores, 2.8 compiles' worth of CPU: the suite
took 5:14 on a fresh clone against 3:48 warm). So the controller compiles them once, before it
starts the workers, in a short run of ``footfall simulate``; warm, this costs about 3 s.
numba compiles on one core, and half of that minute is one kernel, the batch planner's parallel
loop (plan_feet_parallel, 33 of 66 s on a 2-core machine, 2026-11-25). So a second process compiles
it from a one-foot batch while the run compiles the rest, and the run's first planning call waits
for that process (then loads the kernel from the cache) rather than compiling it too.

CI starts it before ``apt-get`` (downloads on a fresh machine, most of a minute) and waits for it before the
test command, whose own warm-up then finds the kernels compiled.
"""

import os
import subprocess
import sys
import tempfile
import time

_PLANNER_WARM_UP = """
import numpy as np
from footfall.planner import FootQuery, GridFrame, LocalMaps, make_batch, plan_batch
n = 35
ground = np.zeros((n, n))
maps = LocalMaps(GridFrame(0.0, 0.0, 0.07, n, n), ground.copy(), ground, np.zeros((n, n), np.uint8))
query = FootQuery(source=(1.2, 0.0, 1.2), preferred=(1.4, 1.2), hip=(1.1, 1.1), reach_xz=0.5, step_height=0.05,
                  foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
plan_batch(make_batch([maps], [(0, query)]), parallel=True)
"""
_RUN_WARM_UP = """
import os, sys, time
import footfall.planner._crowd as crowd
from footfall.cli import main
planned = crowd.plan_batch
def plan_batch(*args, **kwargs):
    for _ in range(3000):  # at most 10 minutes: then compile it here
        if os.path.exists(sys.argv[1]):
            break
        time.sleep(0.2)
    crowd.plan_batch = planned
    return planned(*args, **kwargs)
crowd.plan_batch = plan_batch
main(["simulate", "mixed", "--frames", "3", "--characters", "4", "--json"])  # the way's kernels too (on by default)
"""


def compile_kernels() -> list[str]:
    """Compile the kernels in two processes (cache: ``NUMBA_CACHE_DIR``, as
    :func:`footfall.configure_numba_cache` sets it); returns the last line of each failed process's stderr."""
    errors = []
    with tempfile.TemporaryDirectory(prefix="footfall-warm-up-") as folder:
        planner_done = os.path.join(folder, "planner-compiled")
        # stderr into files: a pipe nobody reads while the other process is awaited could fill and block
        with open(os.path.join(folder, "planner.err"), "w+") as planner_err, \
                open(os.path.join(folder, "run.err"), "w+") as run_err:
            planner = subprocess.Popen([sys.executable, "-c", _PLANNER_WARM_UP], stdout=subprocess.DEVNULL,
                                       stderr=planner_err)
            run = subprocess.Popen([sys.executable, "-c", _RUN_WARM_UP, planner_done], stdout=subprocess.DEVNULL,
                                   stderr=run_err)
            planner.wait(timeout=900)
            open(planner_done, "w").close()  # compiled, or failed: the run goes on either way
            run.wait(timeout=900)
            for proc, err in ((planner, planner_err), (run, run_err)):
                if proc.returncode != 0:  # the tests will say what is wrong, one by one
                    err.seek(0)
                    errors.extend(err.read().strip().splitlines()[-1:])
    return errors


if __name__ == "__main__":
    from footfall import configure_numba_cache

    configure_numba_cache()
    started = time.perf_counter()
    for line in compile_kernels():
        print(f"footfall: a warm-up process failed ({line})")
    print(f"footfall: compiled the numba kernels ({time.perf_counter() - started:.0f} s)")
