"""Behaviour unchanged (issue 17): a seeded recording, a run with each shipped preset (and the preset
files themselves) and the quick report's quality columns equal, bit for bit, what
``tests/data/golden.json`` recorded. A refactor that changes one number fails here; a change meant to
change behaviour regenerates the file (``python tests/golden_runs.py --write``) and says why."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from golden_runs import GOLDEN, PINNED_ENV  # noqa: E402

pytestmark = pytest.mark.slow


def _differences(expected, got, where="") -> list[str]:
    if isinstance(expected, dict) and isinstance(got, dict):
        out = [f"{where}/{k}: missing" for k in expected if k not in got]
        out += [f"{where}/{k}: new" for k in got if k not in expected]
        for k in expected:
            if k in got:
                out += _differences(expected[k], got[k], f"{where}/{k}")
        return out
    return [] if expected == got else [f"{where}: {expected} -> {got}"]


@pytest.fixture(scope="module")
def computed():
    env = dict(os.environ, **PINNED_ENV)
    proc = subprocess.run([sys.executable, str(HERE / "golden_runs.py")], capture_output=True, text=True,
                          timeout=900, env=env)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_the_seeded_runs_and_the_report_columns_are_the_recorded_ones(computed):
    expected = json.loads(GOLDEN.read_text())
    diff = _differences(expected, computed)
    assert not diff, ("behaviour changed (regenerate with `python tests/golden_runs.py --write` only if meant):\n"
                      + "\n".join(diff[:20]))


def test_the_golden_file_covers_every_shipped_preset_and_quality_row(computed):
    # A comparison of empty sections would pass anything: every part holds what it must.
    expected = json.loads(GOLDEN.read_text())
    from footfall.tuning import shipped_preset_paths

    shipped = sorted(p.stem for p in shipped_preset_paths())
    # Every creature's generic preset ships (the terrain and style ones only while the matrix passes them).
    from footfall.scenarios import builtin_creature_names

    assert sorted(expected["presets"]) == shipped and set(builtin_creature_names()) <= set(shipped)
    assert len(expected["recording"]) >= 10 and len(expected["quality"]) == 5
    for fields in expected["quality"].values():
        assert fields["situations"] > 0 and fields["strides"] > 0 and "ms_per_frame" not in fields


def test_the_comparison_sees_one_changed_bit():
    assert _differences({"a": {"b": "0f"}}, {"a": {"b": "0e"}}) == ["/a/b: 0f -> 0e"]
    assert _differences({"a": 1}, {"a": 1, "c": 2}) == ["/c: new"]
