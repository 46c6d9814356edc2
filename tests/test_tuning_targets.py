"""The biomechanics targets file: loads with its citations; a malformed file names file and field."""

import math
import tomllib

import pytest

from footfall._errors import InputError
from footfall.planner._timing import hip_height
from footfall.scenarios import builtin_creature_names, load_creature
from footfall.tuning import QUANTITIES, TARGETS_FILE, load_targets


def test_the_targets_file_loads_for_every_creature_with_citations():
    targets = load_targets()
    assert set(targets) == set(builtin_creature_names())
    for name, t in targets.items():
        assert t.leg_length_m == hip_height(load_creature(name))
        assert set(t.targets) == set(QUANTITIES)
        for quantity, target in t.targets.items():
            assert target.citation.strip(), (name, quantity)
    # Alexander's law, normalised by the leg length: lambda / h = 2.3 Fr^0.3.
    spider = targets["spider"]
    h = spider.leg_length_m
    v = 0.3
    assert spider.stride_length_m(v) == pytest.approx(2.3 * h * (v * v / (9.81 * h)) ** 0.3, rel=1e-12)
    assert spider.clearance_min_m == pytest.approx(spider["clearance"].values["minimum"] * h)
    # Per-creature overrides apply; creatures without one get the defaults.
    assert targets["ant"]["duty_factor"].source == "ting_1994"
    data = tomllib.loads(TARGETS_FILE.read_text(encoding="utf-8"))
    for quantity in QUANTITIES:
        entry = data["creatures"].get("robot5", {}).get(quantity, data["defaults"][quantity])
        loaded = targets["robot5"][quantity]
        assert loaded.source == entry["source"]
        assert loaded.values == {k: float(v) for k, v in entry.items() if k != "source"}
    assert math.isclose(targets["robot5"]["swing_jerk"].values["minimum"], 720.0)  # Flash & Hogan's bound


def _write(tmp_path, text):
    path = tmp_path / "targets.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("old, new, field", [
    ("coefficient = 2.3", "coefficient = -2.3", "defaults.stride_length.coefficient"),
    ("exponent = 0.3", "exponent = 'x'", "defaults.stride_length.exponent"),
    ("relative_tolerance = 0.15", "", "defaults.stride_length.relative_tolerance"),
    ('source = "spagna_2011"\n\n[defaults.swing_jerk]', 'source = "nobody_2024"\n\n[defaults.swing_jerk]',
     "defaults.duty_factor_slope.source"),
    ("maximum = 1000.0", "maximum = 100.0", "defaults.swing_jerk.maximum"),
    ("[creatures.robot5]", "[creatures.octopus]", "creatures.octopus"),
    ("[creatures.ant.duty_factor]\nlow = 0.45", "[creatures.ant.duty_factor]\nlow = 0.9",
     "creatures.ant.duty_factor.high"),
    ("schema_version = 1", "schema_version = 2", "schema_version"),
    ("[defaults.clearance]\n", "[defaults.clearance]\ncolour = 1\n", "defaults.clearance.colour"),
])
def test_a_malformed_targets_file_names_file_and_field(tmp_path, old, new, field):
    text = TARGETS_FILE.read_text(encoding="utf-8")
    assert old in text
    path = _write(tmp_path, text.replace(old, new, 1))
    with pytest.raises(InputError) as info:
        load_targets(path)
    assert info.value.file == str(path)
    assert info.value.field == field


def test_invalid_toml_and_missing_file_are_input_errors(tmp_path):
    path = _write(tmp_path, "schema_version = [")
    with pytest.raises(InputError, match="invalid TOML") as info:
        load_targets(path)
    assert info.value.file == str(path)
    with pytest.raises(InputError, match="cannot read"):
        load_targets(tmp_path / "missing.toml")
