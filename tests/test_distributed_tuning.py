"""Tuning's runs as tasks (issue 6): the harvest's chunks and the exact loss's runs give the
same results, bit for bit, in-process, on local worker processes, and when a worker is
killed mid-run. The clusters listen on loopback only."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import numba
import numpy as np
import pytest

from footfall._distribute import task_runner
from footfall.planner import GaitTiming, Harvest, ScoringWeights
from footfall.planner._harvest import _harvest_batch, pack_harvest
from footfall.tuning._harvest_runs import harvest_chunk, harvest_situations, harvest_tasks
from footfall.tuning._exact import ExactSetup, exact_metrics

pytestmark = pytest.mark.slow  # worker processes (about 12 s)

# Tiny runs: 2 characters so that some frames plan several feet (a cap can fall inside a frame).
HARVEST = dict(scenarios=("flat", "hills"), creatures=("spider",), seeds=(0, 1), frames=12, n_characters=3)
EXACT = ExactSetup("spider", scenarios=("flat", "hills"), frames=60, froude=(0.01, 0.02), n_characters=1)


def sequential_harvest(scenarios, creatures, *, seeds, frames, n_characters, weights=None, timing=None,
                       max_situations=None) -> Harvest:
    """The harvest as it was before the runs became tasks (one loop, one raster per scenario shared
    by its seeds, stop at the end of the frame that reaches the cap): the reference to match."""
    from footfall.planner._crowd import init_crowd, planner_config_for, step
    from footfall.planner._maps import WorldRaster
    from footfall.scenarios import default_gait_name, load_creature, load_gait, load_scenario

    weights = weights or ScoringWeights()
    timing = timing or GaitTiming()
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        rows: list[dict] = []
        for ci, creature_name in enumerate(creatures):
            creature = load_creature(creature_name)
            gait = load_gait(default_gait_name(creature.name), creature)
            cell = planner_config_for(creature).cell_size
            for si, scenario_name in enumerate(scenarios):
                scenario = load_scenario(scenario_name)
                raster = WorldRaster.build(scenario.terrain, scenario.obstacles, cell)
                for seed in seeds:
                    model, state = init_crowd(scenario, creature, gait, n_characters=n_characters, seed=int(seed),
                                              weights=weights, timing=timing, lod_mode="off", raster=raster)
                    meta = {"creature": ci, "scenario": si, "seed": int(seed)}
                    for _ in range(frames):
                        plans = step(model, state).plans
                        if plans is None:
                            continue
                        _harvest_batch(plans.batch, model.weights, model.config, plans.result, plans.chars, plans.legs,
                                       plans.kinds, state, model, meta, rows)
                        if max_situations is not None and len(rows) >= max_situations:
                            return pack_harvest(rows, creatures, scenarios, weights.to_array(), timing.to_array())
        return pack_harvest(rows, creatures, scenarios, weights.to_array(), timing.to_array())
    finally:
        numba.set_num_threads(threads)


def same(a, b) -> bool:
    """Equal, bit for bit: numpy arrays by value and dtype, floats exactly (NaN equals NaN)."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and a.dtype == b.dtype
                and np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return True
    return type(a) is type(b) and a == b


def assert_same_harvest(a: Harvest, b: Harvest) -> None:
    for field in dataclasses.fields(Harvest):
        assert same(getattr(a, field.name), getattr(b, field.name)), field.name


@pytest.fixture(scope="module")
def chunk_sizes():
    """Per chunk (task order), the row count after each harvested frame, uncapped."""
    tasks = harvest_tasks(HARVEST["scenarios"], HARVEST["creatures"], HARVEST["seeds"], HARVEST["frames"],
                          HARVEST["n_characters"], ScoringWeights(), GaitTiming(), None)
    ends = [harvest_chunk(t)["frame_ends"] for t in tasks]
    assert len(ends) == 4 and all(ends), "every chunk should plan something"
    return ends


@pytest.fixture(scope="module")
def caps(chunk_sizes):
    """Caps that cut: at the first situation, at the exact end of chunk 1, inside a multi-foot frame
    of chunk 2 (the whole frame is kept), and beyond everything."""
    first = chunk_sizes[0][-1]
    second = chunk_sizes[1]
    starts = [0] + second[:-1]
    wide = [(s, e) for s, e in zip(starts, second) if e - s > 1]
    assert wide, "chunk 2 should have a frame with several feet"
    s, e = wide[0]
    inside = first + s + 1  # reached in the middle of that frame
    assert first + s < inside < first + e
    return {"one": 1, "end_of_chunk_1": first, "inside_chunk_2": inside, "all": sum(c[-1] for c in chunk_sizes) + 5}


@pytest.fixture(scope="module")
def runner():
    """Two local worker processes, one client for every call of the module's tests."""
    with task_runner(workers=2) as map_tasks:
        yield map_tasks


@pytest.mark.parametrize("cap", ["one", "end_of_chunk_1", "inside_chunk_2", "all", None])
def test_chunked_harvest_is_the_sequential_harvest(cap, caps, chunk_sizes):
    max_situations = None if cap is None else caps[cap]
    reference = sequential_harvest(**HARVEST, max_situations=max_situations)
    chunked = harvest_situations(**HARVEST, max_situations=max_situations)
    assert_same_harvest(chunked, reference)
    if cap == "inside_chunk_2":
        # Whole frames: the frame that reached the cap is kept to its end, and chunks 3 and 4 add nothing.
        assert chunked.n_situations > max_situations
        assert set(chunked.seed[chunk_sizes[0][-1]:]) == {HARVEST["seeds"][1]}
        assert set(chunked.scenario) == {0}


@pytest.mark.parametrize("cap", [None, "inside_chunk_2"])
def test_harvest_on_local_workers_is_the_in_process_harvest(cap, caps, runner):
    max_situations = None if cap is None else caps[cap]
    here = harvest_situations(**HARVEST, max_situations=max_situations)
    there = harvest_situations(**HARVEST, max_situations=max_situations, map_tasks=runner)
    assert_same_harvest(there, here)


def test_exact_metrics_on_local_workers_are_the_in_process_ones(runner):
    weights = dataclasses.replace(ScoringWeights(), **{ScoringWeights.field_names()[0]: 0.7})
    for params in [(None, None), (weights, GaitTiming(duty_slope=0.3))]:
        here = exact_metrics(EXACT, *params)
        there = exact_metrics(EXACT, *params, map_tasks=runner)
        assert same(there.to_json(), here.to_json())
        assert len(here.runs) == 4


def test_a_worker_killed_mid_run_costs_only_its_tasks(runner, kill_a_busy_worker):
    from distributed import default_client

    # Enough tasks that some are still in flight on a worker when the first one finishes.
    setup = dataclasses.replace(EXACT, seeds=(0, 1, 2), frames=60)
    expected = exact_metrics(setup)
    # The runner's own client (the default one while its block is open): the kill hits the
    # task_runner's LocalCluster, whose nanny restarts the worker.
    client = default_client()
    assert client.scheduler.address.startswith("tcp://127.0.0.1:")
    kill, killed = kill_a_busy_worker(client)

    calls = []

    def map_and_kill(function, tasks, progress=None):
        calls.append(len(tasks))
        return runner(function, tasks, progress=kill)

    result = exact_metrics(setup, map_tasks=map_and_kill)
    assert calls == [12]
    assert killed, "no worker was busy: the runs did not go to the cluster"
    assert len(result.runs) == 12
    assert same(result.to_json(), expected.to_json())


def test_in_process_runner_and_planner_stay_without_dask():
    code = ("import sys, footfall.planner._harvest\n"
            "from footfall._distribute import task_runner\n"
            "with task_runner(workers=1) as m:\n"
            "    assert m(lambda t: t['x'] * 2, [{'x': 1}, {'x': 2}]) == [2, 4]\n"
            "    assert m(lambda t: t['x'], []) == []\n"
            "bad = [k for k in sys.modules if k.split('.')[0] in ('dask', 'distributed', 'jax', 'pyvista', 'pxr')]\n"
            "print(bad); sys.exit(1 if bad else 0)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_bad_map_tasks_is_refused():
    with pytest.raises(ValueError, match="map_tasks"):
        harvest_situations(**HARVEST, map_tasks=2)
    with pytest.raises(ValueError, match="map_tasks"):
        exact_metrics(EXACT, map_tasks="tcp://x")
