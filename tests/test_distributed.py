"""Sweeps on Dask workers (issue 6): same results as in-process, and a worker killed
mid-sweep costs only its tasks. The cluster listens on loopback only."""

from __future__ import annotations


import pytest

from footfall._errors import InputError
from footfall._distribute import check_workers, run_tasks
from footfall.reports._sweep import PRESETS, build_tasks, run_task, without_timings

pytestmark = pytest.mark.slow  # worker processes (about 20 s)


@pytest.fixture(scope="module")
def quick_tasks():
    tasks = build_tasks(PRESETS["quick"])
    assert len(tasks) >= 4  # enough to have tasks in flight on both workers when one dies
    return tasks


@pytest.fixture(scope="module")
def in_process(quick_tasks):
    return run_tasks(run_task, quick_tasks, workers=1)


def test_a_worker_killed_mid_sweep_costs_only_its_tasks(quick_tasks, in_process, kill_a_busy_worker):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster, Client(cluster) as client:
        kill, killed = kill_a_busy_worker(client)
        results = run_tasks(run_task, quick_tasks, cluster=cluster.scheduler_address, progress=kill)
    assert killed, "no worker was busy: the sweep did not run on the cluster"
    assert len(results) == len(quick_tasks)
    assert [without_timings(r) for r in results] == [without_timings(r) for r in in_process]


def test_local_worker_processes_give_the_in_process_results(quick_tasks, in_process):
    results = run_tasks(run_task, quick_tasks[:3], workers=2)
    assert [without_timings(r) for r in results] == [without_timings(r) for r in in_process[:3]]


def _fails(task: dict) -> dict:
    if task["k"] == 1:
        raise ValueError(f"task {task['k']} failed")
    return task


def test_a_task_that_fails_on_a_local_worker_raises_in_the_caller():
    # The local workers log only at CRITICAL (a heartbeat's traceback at close is noise), so a task's
    # error must still reach the caller, named.
    with pytest.raises(ValueError, match="task 1 failed"):
        run_tasks(_fails, [{"k": 0}, {"k": 1}], workers=2)


@pytest.mark.parametrize("workers, cluster, field", [(0, None, "--workers"), (2, "tcp://127.0.0.1:1", "--workers"),
                                                     (None, "127.0.0.1:8786", "--cluster")])
def test_bad_worker_options_are_refused(workers, cluster, field):
    with pytest.raises(InputError) as e:
        check_workers(workers, cluster)
    assert e.value.field == field
