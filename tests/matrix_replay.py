"""Stored runs of the preset x terrain matrix, run again now: ``python tests/matrix_replay.py PRESET TERRAIN K...``
prints, as JSON, ``{K: {"default": metrics, "preset": metrics}}`` for the cell's stored runs K.

``tests/test_presets_matrix.py`` runs this in a subprocess with numpy's CPU dispatch held at its
baseline (``golden_runs.PINNED_ENV``), as the matrix was written: numpy's AVX-512 sin/cos round
differently, and on such a machine one stored run's stride error moved in its 17th digit.
"""

from __future__ import annotations

import json
import sys


def replay(name: str, terrain: str, picks: list[int]) -> dict:
    from footfall.planner import load_preset
    from footfall.tuning import PRESETS_DIR, creature_defaults
    from footfall.tuning._events import EventSetup, event_metrics
    from footfall.tuning._matrix import CHARACTERS, MATRIX_FILE, PRESETS, TERRAINS, _repo_path
    from footfall.tuning._targets import load_tune_targets

    cell = json.loads(MATRIX_FILE.read_text())["presets"][name]["cells"][terrain]
    spec = PRESETS[name]
    creature = spec["creature"]
    preset = load_preset(PRESETS_DIR / f"{name}.json", creature)
    targets = load_tune_targets(_repo_path(spec["style"]) if "style" in spec else None, creature)
    out = {}
    for k in picks:
        run = cell["runs"][k]
        setup = EventSetup(creature, (TERRAINS[terrain],), seeds=(run["seed"],), spawn_fractions=(run["spawn"],),
                           n_characters=CHARACTERS.get(terrain, 1))
        out[k] = {}
        for side, weights, timing in (("default", creature_defaults(creature), targets.timing()),
                                      ("preset", preset.weights, preset.timing or targets.timing())):
            live = event_metrics(setup, weights, timing, targets)["runs"][0]
            out[k][side] = {key: live[key] for key in run[side]}
    return out


if __name__ == "__main__":
    from footfall import configure_numba_cache

    configure_numba_cache()
    name, terrain, *ks = sys.argv[1:]
    print(json.dumps(replay(name, terrain, [int(k) for k in ks])))
