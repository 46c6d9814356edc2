"""The runs whose every byte a refactor must keep (issue 17: behaviour unchanged), as hashes.

* ``recording``: a seeded recording (crates-moving, 4 spiders, 60 frames, LOD on): each array of
  the recorder but the stage times (a clock's), hashed with its dtype and shape.
* ``presets``: each shipped preset file's bytes, and a seeded run with it (mixed, 3 characters of
  its creature, 40 frames, LOD off): its recording's arrays.
* ``quality``: the quality columns of the quick report's sweep tasks (every field of a task's
  result that no clock measures, ``reports._sweep.without_timings``), as JSON text.

``python tests/golden_runs.py`` prints the hashes as JSON; ``--write`` stores them in
``tests/data/golden.json`` (after a change meant to change behaviour: say why in the commit).
``tests/test_golden.py`` runs this in a subprocess with numpy's CPU dispatch held at its baseline
(``PINNED_ENV``): numpy's AVX-512 sin/cos/exp round differently from its baseline ones, so a machine
with other vector units would otherwise compute other bits.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

GOLDEN = Path(__file__).resolve().parent / "data" / "golden.json"
PINNED_ENV = {"NPY_DISABLE_CPU_FEATURES": "X86_V3 X86_V4 AVX512_ICL AVX512_SPR"}


CLOCKED_ARRAYS = frozenset({"stage_seconds"})  # measured with a clock: they move with the machine's load


def _arrays_digest(arrays: dict) -> dict:
    import numpy as np

    out = {}
    for name in sorted(set(arrays) - CLOCKED_ARRAYS):
        a = np.ascontiguousarray(arrays[name])
        h = hashlib.sha256(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
        out[name] = h.hexdigest()[:16]
    return out


def _recorded(scenario_name: str, creature_name: str, characters: int, frames: int, seed: int, lod: str,
              preset=None) -> dict:
    from footfall.reports._runs import recorded_run
    from footfall.scenarios import load_creature, load_scenario
    from footfall.scenarios._gait_choice import resolve_gait

    scenario = load_scenario(scenario_name)
    creature = load_creature(creature_name)
    gait, _, _ = resolve_gait(None, creature)  # the creature's default gait (not the scenario's)
    _, _, recorder = recorded_run(scenario, creature, gait, frames=frames, characters=characters, seed=seed,
                                  preset=preset, lod=lod)
    return _arrays_digest(recorder.arrays)


def golden() -> dict:
    from footfall.planner import load_preset
    from footfall.reports._sweep import PRESETS, build_tasks, run_task, without_timings
    from footfall.tuning import shipped_preset_paths

    result = {"recording": _recorded("crates-moving", "spider", 4, 60, 0, "on"), "presets": {}, "quality": {}}
    for path in shipped_preset_paths():
        preset = load_preset(path)
        result["presets"][path.stem] = {"file": hashlib.sha256(path.read_bytes()).hexdigest()[:16],
                                        "run": _recorded("mixed", preset.creature, 3, 40, 0, "off", preset)}
    for task in build_tasks(PRESETS["quick"]):
        if task["kind"] in ("lod", "budget") and task["characters"] <= 4:
            row = without_timings(run_task(task))
            # Through JSON: the values as the report's table stores them (floats exactly, lists for tuples).
            result["quality"][f"{task['scenario']}/{task['setting']}/{task['characters']}"] = json.loads(
                json.dumps(row))
    return result


if __name__ == "__main__":
    import os

    if any(os.environ.get(k) != v for k, v in PINNED_ENV.items()):
        # numpy reads its CPU dispatch when it loads: run again with it pinned, as the test does (written
        # unpinned, on an AVX-512 machine, the quality columns differed in the last bits).
        import subprocess

        sys.exit(subprocess.call([sys.executable, *sys.argv], env=dict(os.environ, **PINNED_ENV)))
    from footfall import configure_numba_cache

    configure_numba_cache()
    values = golden()
    if "--write" in sys.argv[1:]:
        GOLDEN.parent.mkdir(parents=True, exist_ok=True)
        GOLDEN.write_text(json.dumps(values, indent=1, sort_keys=True) + "\n")
    print(json.dumps(values, sort_keys=True))
