"""The command line: one-line errors with exit code 2, and the --json interfaces."""

import json
import subprocess
import sys

import pytest

CLI = [sys.executable, "-m", "footfall.cli"]


def run(*args, cwd=None):
    return subprocess.run(CLI + list(args), capture_output=True, text=True, cwd=cwd, timeout=600)


@pytest.mark.parametrize(
    "content, field",
    [
        ("name = 'x'\n[terrain]\nkind = 'flat'\nsize = [5.0, 5.0]\ncell_size = 0.05\nbogus = 1\n", "bogus"),
        ("[terrain]\nkind = 'flat'\nsize = [5.0, -5.0]\ncell_size = 0.05\n", "terrain.size"),
        ("[terrain]\nkind = 'lava'\nsize = [5.0, 5.0]\ncell_size = 0.05\n", "terrain"),
        ("[terrain\nkind = 'flat'\n", ""),
    ],
)
def test_malformed_scenario_is_one_line_and_exit_2(tmp_path, content, field):
    path = tmp_path / "bad.toml"
    path.write_text(content)
    for command in (["check", str(path)], ["plan", str(path)]):
        proc = run(*command)
        assert proc.returncode == 2, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1, proc.stderr
        assert str(path) in lines[0] and field in lines[0]
        assert "Traceback" not in proc.stderr
        assert proc.stdout == ""


def test_unknown_scenario_and_bad_budget():
    proc = run("plan", "no-such-place")
    assert proc.returncode == 2 and "no-such-place" in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    proc = run("plan", "flat", "--budget", "lavish")
    assert proc.returncode == 2 and "--budget" in proc.stderr


def test_plan_json():
    proc = run("plan", "flat", "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["creature"] == "spider" and len(out["feet"]) == 8
    for foot in out["feet"]:
        assert foot["valid"]
        assert set(foot["breakdown"]) >= {"distance", "slope", "length", "curvature", "clearance", "jerk"}
        assert foot["counters"]["couples_evaluated"] >= 1


def test_bench_planner_json_keys():
    proc = run("bench", "planner", "--json", "--poses", "1", "--repeats", "1")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert set(out["scenarios"]) == {"crates", "mixed"}
    for row in out["scenarios"].values():
        assert set(row) == {"first_valid_us", "default_us", "exhaustive_us"}
        assert all(v > 0 for v in row.values())
    assert out["speedup_vs_per_target"] > 0 and out["speedup_vs_skimage_mcp"] > 0
