"""``footfall evaluate``: the JSON interface, reproducible seeds, --strict, --out, bad input, and the
promise table on hand-made summaries (reports._evaluate.PROMISES)."""

import json

import pytest
from typer.testing import CliRunner

from footfall.cli import app
from footfall.reports._evaluate import PROMISE_NAMES, violations

SMALL = ["flat", "--creatures", "spider", "--seeds", "1", "--frames", "30", "--characters", "2", "--workers", "1"]


def _invoke(*args):
    return CliRunner().invoke(app, ["evaluate", *args])


def _clean_summary(**changes):
    s = dict(collisions=0, forbidden_footprints=0, leg_crossings=0, body_overlaps=0, shared_foot_spots=0,
             unavoidable_contacts=0, max_stance_slip_m=0.0, ik_residual_p95_m=0.0, stuck_seconds=0.0,
             strides_measured=10, stride_rel_error_median=0.01, stride_rel_error_p90=0.05, speed_asked=0.3,
             speed_cap=None, speed_reached=0.3)
    s.update(changes)
    return s


def test_a_clean_run_violates_nothing_and_each_promise_counts_its_own_failure():
    assert set(violations(_clean_summary(), "flat").values()) == {0}
    cases = {
        "collisions": dict(collisions=3), "leg_crossings": dict(leg_crossings=2),
        "body_overlaps": dict(body_overlaps=5), "shared_foot_spots": dict(shared_foot_spots=1),
        "unavoidable_contacts": dict(unavoidable_contacts=4), "stance_slip": dict(max_stance_slip_m=0.0011),
        "ik_residual": dict(ik_residual_p95_m=0.0021), "stuck": dict(stuck_seconds=1.5),
        "stride_error": dict(stride_rel_error_p90=0.16), "speed_reached": dict(speed_reached=0.28),
        "forbidden_footprints": dict(forbidden_footprints=1),
    }
    assert set(cases) == set(PROMISE_NAMES)
    expected = {"collisions": 3, "leg_crossings": 2, "body_overlaps": 5, "shared_foot_spots": 1,
                "unavoidable_contacts": 4, "stance_slip": 1, "ik_residual": 1, "stuck": 2, "stride_error": 1,
                "speed_reached": 1, "forbidden_footprints": 1}
    for name, change in cases.items():
        found = {k: v for k, v in violations(_clean_summary(**change), "flat").items() if v}
        assert found == {name: expected[name]}, name


def test_thresholds_are_inclusive_limits():
    # Exactly at a limit is no violation; the flat bars are tighter than the others.
    at = _clean_summary(max_stance_slip_m=0.001, ik_residual_p95_m=0.002, stride_rel_error_median=0.05,
                        stride_rel_error_p90=0.15, speed_reached=0.95 * 0.3)
    assert set(violations(at, "flat").values()) == {0}
    hills = _clean_summary(stride_rel_error_median=0.08, stride_rel_error_p90=0.2)
    assert violations(hills, "hills")["stride_error"] == 0
    assert violations(hills, "flat@seed=2")["stride_error"] == 1
    # Speed is a promise on flat ground only, against the cap when the asked speed is capped.
    slow = _clean_summary(speed_reached=0.2, speed_cap=0.21)
    assert violations(slow, "flat")["speed_reached"] == 0
    assert violations(_clean_summary(speed_reached=0.1), "hills")["speed_reached"] == 0


def test_json_keys_and_the_same_seed_base_gives_the_same_violations():
    a = _invoke(*SMALL, "--seed-base", "5", "--json")
    assert a.exit_code == 0, a.output
    doc = json.loads(a.stdout)
    assert set(doc) == {"runs", "character_frames", "violations", "failed_runs", "wall_s"}
    assert doc["runs"] == 1 and doc["character_frames"] == 60
    assert set(doc["violations"]) == set(PROMISE_NAMES)
    for run in doc["failed_runs"]:
        assert {"scenario", "creature", "seed", "violations"} <= set(run)
        assert run["seed"] == 5
    b = json.loads(_invoke(*SMALL, "--seed-base", "5", "--json").stdout)
    assert b["violations"] == doc["violations"]


def test_a_capped_creature_is_said_once_not_once_a_run(tmp_path):
    # splay8's speed is capped (0.047 m/s of the 0.3 asked): its runs all say the same note, and a sweep
    # printed it once per run (18 lines a creature over six scenarios and three seeds). Said once now.
    from pathlib import Path

    splay8 = Path(__file__).parent / "data" / "creatures" / "splay8.toml"
    r = _invoke("flat", "--creatures", str(splay8), "--seeds", "3", "--seed-base", "1", "--frames", "2",
                "--characters", "1", "--workers", "1", "--json")
    assert r.exit_code == 0, r.output
    lines = [line for line in r.stderr.splitlines() if line.startswith("footfall: note: splay8:")]
    assert lines == ["footfall: note: splay8: 0.3 m/s asked; speed capped at 0.0469 m/s, the fastest its legs carry "
                     "at the stride law where each foot lands a foot's room clear of the neighbouring leg and its foot"]
    assert json.loads(r.stdout)["runs"] == 3


def test_random_seeds_are_printed(monkeypatch):
    r = CliRunner().invoke(app, ["evaluate", *SMALL, "--json"])
    assert r.exit_code == 0
    assert "seeds: " in r.stderr


def test_strict_fails_on_a_violation_and_a_plain_run_reports_it(monkeypatch, tmp_path):
    import footfall.reports._evaluate as ev

    # A promise that every run breaks: a run walking at all "collides".
    broken = ev.Promise("collisions", "every run", lambda s, _n: 1)
    monkeypatch.setattr(ev, "PROMISES", (broken,) + ev.PROMISES[1:])
    plain = _invoke(*SMALL, "--seed-base", "0", "--out", str(tmp_path / "ev"))
    assert plain.exit_code == 0, plain.output
    assert "footfall simulate flat --creature spider --seed 0 --characters 2 --frames 30 --lod off" in plain.stdout
    for name in ("index.html", "evaluate.json", "runs.csv", "worst-0.png"):
        assert (tmp_path / "ev" / name).stat().st_size > 0, name
    header = (tmp_path / "ev" / "runs.csv").read_text().splitlines()[0].split(",")
    assert len(header) == len(set(header)), header  # a reader by column name gets every column
    assert {"speed_reached", "speed_reached_m_s", "box_shoves", "stuck_seconds"} <= set(header)
    assert _invoke(*SMALL, "--seed-base", "0", "--strict").exit_code == 1


@pytest.mark.parametrize("args, field", [
    (["nowhere"], "nowhere"),
    (["flat", "--creatures", "unicorn"], "unicorn"),
    (["flat", "--seeds", "0"], "--seeds"),
    (["flat", "--frames", "-5"], "--frames"),
    (["flat", "--lod", "maybe"], "--lod"),
    (["flat", "--workers", "2", "--cluster", "tcp://h:8786"], "--workers"),
])
def test_bad_input_is_one_line_and_exit_2(args, field):
    from conftest import footfall_cli

    proc = footfall_cli("evaluate", *args)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("footfall: error:") and field in lines[0], proc.stderr


def test_a_preset_walks_every_run_and_its_replay_says_so(monkeypatch):
    # The ant-stairs preset on a stairs run: the run is `simulate --preset`'s, not the defaults'.
    import footfall.reports._evaluate as ev
    from conftest import footfall_cli

    args = ["stairs", "--creatures", "ant", "--seeds", "1", "--seed-base", "3", "--frames", "60", "--characters", "1",
            "--workers", "1", "--json"]
    runs = {}
    real = ev.run_one
    monkeypatch.setattr(ev, "run_one", lambda task: runs.setdefault(task["preset"], real(task)))
    for extra in ([], ["--preset", "ant-stairs"]):
        done = _invoke(*args, *extra)
        assert done.exit_code == 0, done.output
    plain, tuned = runs[None]["summary"], runs["ant-stairs"]["summary"]
    planned = ("cells_expanded", "couples_evaluated", "stride_rel_error_median")
    assert [plain[k] for k in planned] != [tuned[k] for k in planned]  # the preset chose other footprints
    replay = ev.replay_command(runs["ant-stairs"])
    assert replay.endswith("--lod off --preset ant-stairs --json")
    proc = footfall_cli(*replay.split()[1:])  # ... and replaying it measures the same run
    assert proc.returncode == 0, proc.stderr
    replayed = json.loads(proc.stdout)
    for key in ("steps", "plans", "holds", *planned, "max_stance_slip_m"):
        assert replayed[key] == tuned[key], key


def test_a_preset_for_another_creature_is_one_line_and_exit_2():
    from conftest import footfall_cli

    proc = footfall_cli("evaluate", "flat", "--creatures", "ant,spider", "--preset", "ant-stairs", "--seeds", "1")
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("footfall: error:") and "ant-stairs" in lines[0], proc.stderr
    proc = footfall_cli("evaluate", "flat", "--creatures", "ant", "--preset", "no-such-preset", "--seeds", "1")
    assert proc.returncode == 2 and "--preset" in proc.stderr, proc.stderr
