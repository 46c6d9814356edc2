"""Weight presets: the runtime loads them, and refuses ones made for something else."""

import json
import subprocess
import sys

import pytest
from conftest import footfall_cli

from footfall import InputError
from footfall.planner import GaitTiming, ScoringWeights, load_preset, preset_dict


def _write(tmp_path, data, name="p.json"):
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return path


def test_round_trip(tmp_path):
    w = ScoringWeights(footprint_distance=2.5, jerk_ref=1234.5)
    t = GaitTiming(duty_at_rest=0.7)
    p = load_preset(_write(tmp_path, preset_dict("spider", w, t, "spider-metachronal-wave")), "spider")
    assert p.weights == w and p.timing == t and p.gait == "spider-metachronal-wave"


@pytest.mark.parametrize(
    "mutate, field",
    [
        (lambda d: d.update(creature="ant"), "creature"),
        (lambda d: d.update(schema_version=99), "schema_version"),
        (lambda d: d["weights"].pop("jerk_ref"), "weights.jerk_ref"),
        (lambda d: d["weights"].update(bogus=1.0), "weights.bogus"),
        (lambda d: d["weights"].update(slope_critical_rad=-1.0), "weights"),
        (lambda d: d.update(extra=1), "extra"),
    ],
)
def test_bad_presets_are_refused_naming_the_field(tmp_path, mutate, field):
    data = preset_dict("spider", ScoringWeights(), GaitTiming())
    mutate(data)
    path = _write(tmp_path, data)
    with pytest.raises(InputError) as e:
        load_preset(path, "spider")
    assert str(path) in str(e.value) and field in str(e.value) and "\n" not in str(e.value)


def test_cli_refuses_a_preset_for_another_creature(tmp_path):
    path = _write(tmp_path, preset_dict("ant", ScoringWeights()))
    proc = footfall_cli("simulate", "flat", "--frames", "2", "--preset", path)
    assert proc.returncode == 2 and str(path) in proc.stderr and "creature" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_cli_takes_a_shipped_preset_by_name_and_refuses_an_unknown_name():
    def simulate(preset):
        return footfall_cli("simulate", "flat", "--frames", "3", "--preset", preset, "--json")

    proc = simulate("spider")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["frames"] == 3
    proc = simulate("spidr")
    assert proc.returncode == 2 and "--preset" in proc.stderr and "spider" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    proc = simulate("ant")  # a shipped preset of another creature
    assert proc.returncode == 2 and "ant.json" in proc.stderr and "creature" in proc.stderr


def test_importing_tuning_for_its_presets_and_targets_does_not_load_jax():
    code = ("import sys, footfall.tuning as tuning, footfall.tuning._targets; tuning.PRESETS_DIR; tuning._targets.load_targets(); "
            "assert 'jax' not in sys.modules, 'jax loaded'")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr


def test_a_tunes_checkpoint_beside_the_shipped_presets_is_not_one_of_them(tmp_path, monkeypatch):
    # `footfall tune --out tuning/data/presets/NAME.json` leaves NAME.json.checkpoint.json beside it: it was
    # read as a preset, and `footfall scenarios` stopped on it (KeyError: 'creature').
    import footfall.tuning as tuning
    from footfall.cli._commands import shipped_presets

    (tmp_path / "spider.json").write_text(json.dumps({"creature": "spider"}))
    (tmp_path / "spider.json.checkpoint.json").write_text(json.dumps({"format": "checkpoint"}))
    monkeypatch.setattr(tuning, "PRESETS_DIR", tmp_path)
    assert [p.name for p in tuning.shipped_preset_paths()] == ["spider.json"]
    assert [row[:2] for row in shipped_presets()] == [("spider", "spider")]
