"""Running independent tasks in-process, on local worker processes, or on a Dask cluster.

A task is a plain dict that carries every input of its run (scenario name, seed, setting,
crowd size...); the function that runs it is a module-level function returning a plain
dict. Nothing depends on worker-local state, so a task gives the same result wherever
it runs, and a task lost with its worker (a killed process) is simply run again on
another one: Dask reschedules the tasks of a lost worker, and ``retries`` covers a task
that raised on a worker that was going down.

* ``workers == 1`` and no ``cluster``: a plain loop in this process (no Dask at all);
* no ``cluster``: a ``LocalCluster`` of ``workers`` processes (default: one per core),
  one thread each, on loopback; on every worker the planner's numba kernels run on one
  thread too (the workers share out the cores);
* ``cluster="tcp://host:8786"``: the workers of an existing scheduler (``dask scheduler``
  on one machine, ``dask worker tcp://host:8786`` on each of the others).

Results come back in task order, whatever order the workers finish in. :func:`task_runner`
keeps one client (and local cluster) for many calls; :func:`run_tasks` is one call.
"""

from __future__ import annotations

import functools
import logging
import os
from contextlib import contextmanager
from typing import Callable, Iterator, Sequence

from footfall._errors import InputError

TASK_RETRIES = 3
"""Times a task that raised on a worker is run again before the sweep fails."""
CONNECT_TIMEOUT_S = 20.0
"""How long to wait for a scheduler given by ``--cluster`` before a one-line error."""


def default_workers() -> int:
    """One local worker process per core."""
    return max(1, os.cpu_count() or 1)


def check_workers(workers: int | None, cluster: str | None) -> int | None:
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise InputError("argument", "--workers", f"expected an integer >= 1, got {workers!r}")
    if cluster is not None:
        if not isinstance(cluster, str) or "://" not in cluster:
            raise InputError("argument", "--cluster", f"expected a scheduler address like tcp://host:8786, got {cluster!r}")
        if workers is not None:
            raise InputError("argument", "--workers", "the workers of a --cluster are its own; drop --workers")
    return workers


def run_tasks(function: Callable[[dict], dict], tasks: Sequence[dict], *, workers: int | None = None,
              cluster: str | None = None, progress: Callable[[dict, int], None] | None = None) -> list[dict]:
    """``[function(task) for task in tasks]``, distributed as the module docstring says.

    ``progress(task, completed)`` is called as each task finishes (in completion order).
    """
    with task_runner(workers=workers, cluster=cluster) as map_tasks:
        return map_tasks(function, tasks, progress=progress)


MapTasks = Callable[..., list]
"""``map_tasks(function, tasks, progress=None) -> list``: what :func:`task_runner` yields."""


@contextmanager
def task_runner(workers: int | None = None, cluster: str | None = None) -> Iterator[MapTasks]:
    """Yield ``map_tasks(function, tasks, progress=None)``, which returns ``[function(task) for task in tasks]``
    (in task order) distributed as the module docstring says, for as many calls as the block makes.

    One client (and local cluster) serves every call: a tune maps about ten small task lists, and
    starting a ``LocalCluster`` costs seconds each time. ``progress(task, completed)`` is called as
    each task finishes (in completion order). The cluster is closed when the block exits.
    """
    workers = check_workers(workers, cluster)
    if cluster is None and (workers or default_workers()) == 1:
        # No Dask at all: importing distributed alone costs about a second.
        yield _map_in_process
        return
    from distributed import Client, LocalCluster

    local = None
    try:
        if cluster is None:
            # Loopback only, no dashboard: nothing listens beyond this machine. The workers' own logs only
            # at CRITICAL: closing the cluster on a busy machine, a worker's last heartbeat found the
            # scheduler gone and printed a 30-line traceback under a finished `footfall evaluate`. A task's
            # error still reaches the caller (the client raises it).
            local = LocalCluster(n_workers=workers or default_workers(), threads_per_worker=1, processes=True,
                                 host="127.0.0.1", dashboard_address=None, silence_logs=logging.CRITICAL)
            client = Client(local)
        else:
            try:
                client = Client(cluster, timeout=CONNECT_TIMEOUT_S)
            except (OSError, TimeoutError) as e:
                raise InputError("argument", "--cluster", f"cannot reach the scheduler {cluster}: {e}") from None
        with client:
            yield functools.partial(_map_on_client, client)
    finally:
        if local is not None:
            local.close()


def _no_progress(task: dict, done: int) -> None:
    pass


def _map_in_process(function: Callable[[dict], dict], tasks: Sequence[dict],
                    progress: Callable[[dict, int], None] | None = None) -> list:
    progress = progress or _no_progress
    results = []
    for k, task in enumerate(tasks):
        # A copy, as a worker would get: a function that edits its task cannot change the caller's.
        results.append(function(dict(task)))
        progress(task, k + 1)
    return results


def _single_threaded(function, task: dict) -> dict:
    """Run a task on a worker with the planner's kernels on one thread: the workers already
    share out the cores, and numba's parallel loops crawl when two processes each spread
    over every core (results are the same: the kernels are bit-identical serial and parallel)."""
    import numba

    numba.set_num_threads(1)
    return function(task)


def _map_on_client(client, function: Callable[[dict], dict], tasks: Sequence[dict],
                   progress: Callable[[dict, int], None] | None = None) -> list:
    from distributed import as_completed

    tasks = list(tasks)
    progress = progress or _no_progress
    if not tasks:
        return []
    # pure=False: two equal tasks are still two runs, and a later call never reuses an earlier
    # call's futures (keys are fresh each time).
    futures = client.map(_single_threaded, [function] * len(tasks), [dict(t) for t in tasks], pure=False,
                         retries=TASK_RETRIES)
    index = {f.key: k for k, f in enumerate(futures)}
    results: list = [None] * len(tasks)
    done = 0
    for future, result in as_completed(futures, with_results=True):
        k = index[future.key]
        results[k] = result
        done += 1
        progress(tasks[k], done)
    return results
