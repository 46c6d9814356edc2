"""The command line: one-line errors with exit code 2, and the --json interfaces."""

import json
import subprocess
import sys

import pytest
from conftest import footfall_cli  # the many bad-input cases run in-process (conftest says why)

CLI = [sys.executable, "-m", "footfall.cli"]


def run(*args, cwd=None):
    return subprocess.run(CLI + list(args), capture_output=True, text=True, cwd=cwd, timeout=600)


def test_check_says_how_the_scoring_scales_fit_a_creature():
    # The beetle's rest radius is 0.345 of the spider's: its default weights' metre scales are scaled so.
    from pathlib import Path

    beetle = Path(__file__).parent / "data" / "creatures" / "beetle.toml"
    done = footfall_cli("check", str(beetle))
    assert done.returncode == 0, done.stderr
    assert "rest radius 0.123 m (the scoring's metre scales x0.35 of the spider's)" in done.stdout
    done = footfall_cli("check", "spider")
    assert done.returncode == 0 and "(the scoring's metre scales the spider's)" in done.stdout, done.stdout


def test_check_says_how_fast_a_creature_walks_and_what_caps_it():
    # A user who writes a dense creature learns before running it that it walks slowly, and why: the
    # cap init_crowd gives a crowd of it (planner._workspace.speed_caps).
    from pathlib import Path

    from footfall.planner import init_crowd
    from footfall.scenarios import load_creature, load_scenario
    from footfall.scenarios._gait_choice import resolve_gait

    splay8 = Path(__file__).parent / "data" / "creatures" / "splay8.toml"
    done = footfall_cli("check", str(splay8))
    assert done.returncode == 0, done.stderr
    creature = load_creature(str(splay8))
    model, _ = init_crowd(load_scenario("flat"), creature, resolve_gait(None, creature)[0], n_characters=1)
    assert (f"splay8 walks at most {model.speed_cap:.3g} m/s, the fastest its legs carry at the stride law where "
            "each foot lands a foot's room clear of the neighbouring leg and its foot") in done.stderr
    done = footfall_cli("check", "robot5")
    assert "robot5 walks at most 2.06 m/s" in done.stderr and "stance windows" in done.stderr, done.stderr


STANDS_STILL = """name = "rc4"
description = "Random creature rc4 of tests/random_creatures.py 31 8: long hind shins, hips 9 mm high."
standing_height = 0.0087
body_thickness = 0.0044
body_box = [0.0480, 0.0222]
foot = { length = 0.0033, width = 0.0025 }

[leg_defaults]
joint_limits = [[-1.2, 0.8], [0.0, 2.4]]

[[legs]]
name = "L1"
hip = [0.0108, 0.0, 0.0100]
rest_foot = [0.0173, 0.0355]
segments = [0.0185, 0.0156]

[[legs]]
name = "R1"
hip = [0.0108, 0.0, -0.0100]
rest_foot = [0.0173, -0.0355]
segments = [0.0185, 0.0156]

[[legs]]
name = "L2"
hip = [-0.0108, 0.0, 0.0100]
rest_foot = [-0.0204, 0.0462]
segments = [0.0168, 0.0410]

[[legs]]
name = "R2"
hip = [-0.0108, 0.0, -0.0100]
rest_foot = [-0.0204, -0.0462]
segments = [0.0168, 0.0410]

"""


def test_check_warns_of_a_creature_that_cannot_walk(tmp_path):
    # A random creature (tests/random_creatures.py 31 8, rc4): its hind legs reach their rest feet and no
    # further at its standing height, so their stance windows are empty and its speed is capped at 0: in
    # every run of footfall evaluate it stood where it spawned. footfall check says so, naming the legs.
    path = tmp_path / "rc4.toml"
    path.write_text(STANDS_STILL)
    done = footfall_cli("check", str(path))
    assert done.returncode == 0, done.stderr
    assert (f"footfall: warning: {path}: rc4 cannot walk: legs L2, R2 carry no stance at its standing height"
            in done.stderr), done.stderr
    assert "walks at most" not in done.stderr


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
        proc = footfall_cli(*command)
        assert proc.returncode == 2, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1, proc.stderr
        assert str(path) in lines[0] and field in lines[0]
        assert "Traceback" not in proc.stderr
        assert proc.stdout == ""


def test_unknown_scenario_and_bad_budget():
    # Real processes: the entry point itself turns bad input into one line and exit code 2.
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


# ----------------------------------------------------------------------------- every bad option value: one line

TERAIN = "name = 'x'\n[terain]\nkind = 'flat'\nsize = [5.0, 5.0]\ncell_size = 0.05\n[crowd]\ncreature = 'spider'\n" \
         "goal = [1.0, 0.0]\n"
"""A scenario whose [terrain] section is misspelt."""

BAD_INPUTS = [
    # (arguments, a piece of the one error line)
    (["simulate", "--frames", "-5"], "argument: --frames: must be >= 1, got -5"),
    (["simulate", "--frames", "abc"], "argument: --frames: expected an integer, got abc"),
    (["simulate", "--frames"], "argument: --frames: requires an argument"),
    (["simulate", "--characters", "0"], "argument: --characters: must be >= 1"),
    (["simulate", "--seed", "x"], "argument: --seed: expected an integer"),
    (["simulate", "--lod", "maybe", "--frames", "1"], "argument: --lod: expected one of on, zoomed, off"),
    (["simulate", "--record", "out.txt"], "argument: --record: expected a .npz path"),
    (["simulate", "--bogus"], "argument: --bogus: no such option"),
    (["simulate", "--jsn"], "did you mean --json?"),
    (["simulate", "--json=1"], "argument: --json: does not take a value"),
    (["simulate", "flat", "extra"], "argument: extra: unexpected extra argument"),
    (["simulate", "no-such-place"], "no-such-place: scenario: unknown scenario"),
    (["simulate", "--preset", "nosuch"], "argument: --preset:"),
    (["plan", "flat", "--budget", "lavish"], "argument: --budget: expected one of"),
    (["plan", "flat", "--step", "-1"], "argument: --step: expected a positive number"),
    (["evaluate", "--seeds", "0"], "argument: --seeds:"),
    (["evaluate", "--lod", "sometimes"], "argument: --lod:"),
    (["run", "--workers", "abc"], "argument: --workers: expected an integer"),
    (["report", "--quick", "--full"], "argument: --quick/--full:"),
    (["tune"], "argument: --creature: required"),
    (["tune", "--creature", "nosuch"], "unknown creature"),
    (["export-usd"], "argument: --out: required"),
    (["export-usd", "--out", "scene.txt"], "expected a .usda, .usdc, .usd file name"),
    (["bench", "crowd", "--frames", "0"], "argument: --frames: must be >= 1"),
    (["bench", "nosuch"], "argument: nosuch: no such command of footfall bench"),
    (["simulat"], "argument: simulat: no such command of footfall; did you mean simulate?"),
    (["check", "{terain}"], "terain: unknown section; did you mean terrain?"),
]


@pytest.mark.parametrize("args, expected", BAD_INPUTS, ids=[" ".join(a) for a, _ in BAD_INPUTS])
def test_every_bad_input_is_one_line_and_exit_2(tmp_path, args, expected):
    terain = tmp_path / "terain.toml"
    terain.write_text(TERAIN)
    proc = footfall_cli(*[a.replace("{terain}", str(terain)) for a in args], cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr  # no blank line, no box, no usage line, no traceback
    assert lines[0].startswith("footfall: error: "), lines[0]
    assert expected in lines[0], lines[0]
    assert list(tmp_path.iterdir()) == [terain]  # nothing written


# ----------------------------------------------------------------------------- help, listing, progress, timing


def test_help_shows_flags_as_flags_and_one_line_summaries():
    proc = run("simulate", "--help")
    assert proc.returncode == 0
    assert "--json" in proc.stdout and "<bool>" not in proc.stdout
    import os

    wide = subprocess.run(CLI + ["--help"], capture_output=True, text=True, timeout=600,
                          env=dict(os.environ, COLUMNS="200"))
    listing = wide.stdout[wide.stdout.index("Commands"):].splitlines()[1:-1]
    # Each command's summary is one line (its docstring's first paragraph): no row continues the one before.
    continued = [line for line in listing if line.startswith("│" + " " * 6)]
    assert listing and not continued, wide.stdout


def test_version_is_the_one_pyproject_declares():
    import tomllib
    from pathlib import Path

    import footfall

    declared = tomllib.loads((Path(__file__).resolve().parent.parent / "pyproject.toml").read_text())["project"]["version"]
    assert footfall.__version__ == declared
    done = footfall_cli("--version")
    assert (done.returncode, done.stdout, done.stderr) == (0, f"footfall {declared}\n", "")


def test_scenarios_lists_descriptions_creatures_and_gaits():
    proc = run("scenarios")
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert "mixed (default)" in out and "3 x spider" in out and "rolling hills" in out
    assert "8 legs" in out and "spider-metachronal-wave, then spider-alternating-tetrapod from Fr 0.2" in out
    assert "quadruped-trot" in out and "Diagonal pairs" in out
    # Every shipped preset, each with its creature and what it is for (its kind read from tuning._matrix).
    from footfall.tuning import shipped_preset_paths
    from footfall.tuning._matrix import PRESETS

    rows = {line.split()[0]: line.split(None, 2)[1:] for line in out.split("Presets (")[1].splitlines()[1:]}
    shipped = {p.stem for p in shipped_preset_paths()}
    assert set(rows) == shipped and {"spider", "quadruped-stairs"} <= shipped
    for name, (creature, what) in rows.items():
        spec = PRESETS.get(name)
        assert creature == (spec["creature"] if spec else name)
        kind = "generic" if spec is None else ("terrain" if "terrain" in spec else "style")
        assert what.startswith(kind + ":"), (name, what)


def test_progress_off_a_terminal_prints_a_line_per_step_and_every_few_seconds():
    import io
    import time

    from footfall.cli._progress import Progress

    stream = io.StringIO()
    with Progress("footfall run", interval=0.2, stream=stream) as bar:
        assert stream.getvalue() == ""  # nothing before the first update
        bar.update("[1/2] simulate: 3 x spider", step="simulate")
        bar.update("[1/2] simulate: more", step="simulate")  # same step, too soon: no line
        time.sleep(0.5)  # the work reports nothing: the display still says it is alive
        bar.update("[2/2] tune: round 1", step="tune")
    lines = stream.getvalue().splitlines()
    assert lines[0] == "footfall run: [1/2] simulate: 3 x spider (0 s)"
    assert any(line.startswith("footfall run: [1/2] simulate: more (") for line in lines[1:-1])
    assert lines[-1].startswith("footfall run: [2/2] tune: round 1 (")
    assert all(line.endswith(" s)") for line in lines)
    quiet = io.StringIO()
    with Progress("footfall run", enabled=False, stream=quiet) as bar:
        bar.update("x", step="simulate")
    assert quiet.getvalue() == ""


def test_simulate_separates_warmup_from_steady_frames():
    proc = run("simulate", "flat", "--frames", "4", "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["ms_per_frame_warmup"] > 0 and out["ms_per_frame_steady"] > 0
    mean = (out["ms_per_frame_warmup"] + 3 * out["ms_per_frame_steady"]) / 4
    assert abs(out["ms_per_frame_mean"] - mean) < 1e-6 * max(1.0, mean)
