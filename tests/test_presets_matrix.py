"""The terrain and style presets and their proof (issue 18, items 4-5): the stored preset x terrain
matrix (``footfall bench presets``) says which presets pass; only those ship, each differs from the
defaults, and the matrix's numbers are reproduced by live runs."""

import json
from pathlib import Path

import numpy as np
import pytest

from planner import load_preset

ROOT = Path(__file__).resolve().parents[1]
PRESETS_DIR = ROOT / "tuning" / "data" / "presets"
MIN_WEIGHT_CHANGE = 0.20  # issue 18 item 4: some weight by >= 20 %


def _matrix():
    from tuning._matrix import MATRIX_FILE

    if not MATRIX_FILE.exists():
        pytest.skip("no stored matrix (footfall bench presets --out tuning/data/matrix.json)")
    return json.loads(MATRIX_FILE.read_text())


def _shipped():
    from tuning._matrix import PRESETS

    return [name for name in PRESETS if (PRESETS_DIR / f"{name}.json").exists()]


def test_the_matrix_proves_every_preset_with_enough_paired_runs():
    from tuning._matrix import PRESETS, RUNS, TERRAINS

    m = _matrix()
    assert m["runs_per_cell"] >= RUNS >= 30
    assert set(m["presets"]) == set(PRESETS) and set(m["terrains"]) == set(TERRAINS)
    for name, p in m["presets"].items():
        if not p["found"] or not p["cells"]:  # not there, or its tune kept the defaults (why says so)
            assert not p["passes"] and p["why"]
            continue
        assert set(p["cells"]) == set(TERRAINS)
        for terrain, cell in p["cells"].items():
            assert cell["main"]["n"] >= 0.8 * m["runs_per_cell"], (name, terrain)  # runs with >= 3 strides


def test_only_presets_that_pass_ship_and_each_is_the_file_the_matrix_proved():
    """A shipped terrain or style preset passed in the stored matrix, with its exact bytes (sha256);
    a preset that did not pass is not in tuning/data/presets/."""
    import hashlib

    m = _matrix()
    for name, p in m["presets"].items():
        path = PRESETS_DIR / f"{name}.json"
        if path.exists():
            assert p["found"] and p["passes"], (name, p.get("why"))
            assert hashlib.sha256(path.read_bytes()).hexdigest() == p["sha256"], name
        else:
            assert not p.get("passes"), name


def test_a_shipped_terrain_preset_beats_the_defaults_at_home_and_loses_nowhere():
    from tuning._matrix import LOSS_SE, PRESETS, WIN_SE

    m = _matrix()
    for name in _shipped():
        p = m["presets"][name]
        spec = PRESETS[name]
        for terrain, cell in p["cells"].items():
            assert not cell["collisions_rise"], (name, terrain)
            if "terrain" in spec:
                bound = WIN_SE if terrain == spec["terrain"] else -LOSS_SE
                assert cell["main"]["gain_se"] >= bound, (name, terrain, cell["main"])
        if "terrains" in spec:
            first = next(iter(p["style"]))
            for terrain in spec["terrains"]:
                assert p["cells"][terrain]["style"][first]["gain_se"] >= WIN_SE, (name, terrain)


@pytest.mark.parametrize("name", ["spider-stairs", "quadruped-stairs", "ant-crates", "spider-mixed", "spider-cautious",
                                  "spider-direct"])
def test_a_shipped_preset_differs_from_the_defaults_and_records_its_tune(name):
    from planner import ScoringWeights
    from tuning._matrix import PRESETS

    path = PRESETS_DIR / f"{name}.json"
    if not path.exists():
        pytest.skip(f"{name} does not ship (it did not pass the matrix; tuning/data/matrix.json says why)")
    spec = PRESETS[name]
    preset = load_preset(path, spec["creature"])
    w = preset.weights.to_array()
    w0 = ScoringWeights().to_array()
    assert np.max(np.abs(w / w0 - 1.0)) >= MIN_WEIGHT_CHANGE
    summary = preset.provenance["summary"]
    for key in ("scenarios", "targets", "heldout_loss_default", "heldout_loss_tuned", "heldout_gain_se",
                "weights_max_rel_change", "spearman_metric_change"):
        assert key in summary
    assert summary["heldout_loss_tuned"] < summary["heldout_loss_default"]
    # The timing is the targets file's stride law: what the runtime commands.
    law = summary["targets"]["stride_length"]
    assert (preset.timing.stride_coefficient, preset.timing.stride_exponent) == (law["coefficient"], law["exponent"])


@pytest.mark.slow
def test_one_cell_of_the_matrix_is_reproduced_by_live_runs():
    """The first shipped preset's cell on its own terrain (or first terrain), recomputed run by run:
    the same numbers (the runs are deterministic), so the matrix is what the presets do now."""
    from tuning._matrix import PRESETS, run_matrix

    m = _matrix()
    names = _shipped()
    if not names:
        pytest.skip("no terrain or style preset ships")
    name = names[0]
    spec = PRESETS[name]
    terrain = spec.get("terrain") or spec["terrains"][0]
    live = run_matrix(PRESETS_DIR, (name,), runs=m["runs_per_cell"], terrains=(terrain,))
    assert live["presets"][name]["cells"][terrain] == m["presets"][name]["cells"][terrain]
