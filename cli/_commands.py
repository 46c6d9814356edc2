"""The ``footfall`` command line.

Every command turns bad input into one line on stderr, ``footfall: error: FILE:
FIELD: REASON``, and exit code 2; ``--json`` output is one JSON object on stdout.
"""

from __future__ import annotations

import json
import math
import sys
from typing import Optional

import typer
import typer.core
import typer.main
from rich.console import Console
from rich.table import Table

from footfall._errors import InputError

try:  # typer >= 0.20 carries its own copy of click
    from typer._click import exceptions as click_exceptions
except ImportError:  # pragma: no cover - an older typer on plain click
    from click import exceptions as click_exceptions

app = typer.Typer(no_args_is_help=True, add_completion=False, pretty_exceptions_enable=False,
                  help="footfall: procedural locomotion of multi-legged characters (Abdul Karim et al., CAVW 2012).")
bench_app = typer.Typer(no_args_is_help=True, help="Benchmarks: tables of measured speed.")
app.add_typer(bench_app, name="bench")


def _print_version(show: bool) -> None:
    if show:
        from footfall import __version__

        print(f"footfall {__version__}")
        raise typer.Exit()


@app.callback()
def _root(version: bool = typer.Option(False, "--version", callback=_print_version, is_eager=True,
                                       help="Print the version (pyproject.toml's) and exit.")) -> None:
    """footfall: procedural locomotion of multi-legged characters (Abdul Karim et al., CAVW 2012)."""

BUDGET_NAMES = ("first-valid", "default", "exhaustive")


def _stdout() -> Console:
    return Console(highlight=False)


def _err() -> Console:
    return Console(stderr=True, highlight=False)


def _budget(name: str):
    from footfall.planner import DEFAULT_BUDGET, EXHAUSTIVE, FIRST_VALID

    budgets = dict(zip(BUDGET_NAMES, (FIRST_VALID, DEFAULT_BUDGET, EXHAUSTIVE)))
    if name not in budgets:
        raise InputError("argument", "--budget", f"expected one of {', '.join(BUDGET_NAMES)}, got {name!r}")
    return budgets[name]


def _finite(x: float):
    return x if math.isfinite(x) else None


LOD_MODES = ("on", "zoomed", "off")


def _check_lod(value: str) -> None:
    """``--lod`` is checked before any work starts, so that its error line is the only output."""
    if value not in LOD_MODES:
        raise InputError("argument", "--lod", f"expected one of {', '.join(LOD_MODES)}, got {value!r}")


@app.command("scenarios")
def scenarios_cmd() -> None:
    """List the built-in scenarios, creatures and gaits, with what each one is."""
    import tomllib

    from footfall.scenarios import (DEFAULT_SCENARIO, builtin_creature_names, builtin_scenario_names, load_creature, load_gait,
                           load_scenario)
    from footfall.scenarios._files import CREATURES_DIR
    from footfall.scenarios._gait_schedule import BUILTIN_SCHEDULES
    from footfall.scenarios._gaits import builtin_gait_names, default_gait_name

    lines = ["Scenarios (footfall run|simulate|report|... NAME, or a .toml; NAME@key=value for a variant):"]
    for name in builtin_scenario_names():
        s = load_scenario(name)
        crowd = f"{s.crowd.count} x {s.crowd.creature}"
        lines.append(f"  {name + (' (default)' if name == DEFAULT_SCENARIO else ''):18} {crowd:12} {s.description}")
    lines.append("Creatures (--creature NAME, or a .toml):")
    gait_owner: dict[str, str] = {}
    for name in builtin_creature_names():
        c = load_creature(name)
        with open(CREATURES_DIR / f"{name}.toml", "rb") as fh:
            description = tomllib.load(fh).get("description", "")
        lines.append(f"  {name:18} {f'{c.n_legs} legs':12} {description}")
        gaits = builtin_gait_names(c)
        for gait in gaits:
            gait_owner.setdefault(gait, name)
        if name in BUILTIN_SCHEDULES:
            names, froude = BUILTIN_SCHEDULES[name]
            walk = ", then ".join(f"{g} from Fr {f:g}" if k else g
                                  for k, (g, f) in enumerate(zip(names, (0.0,) + tuple(froude))))
            lines.append(f"  {'':18} {'':12} gaits by speed: {walk}")
        else:
            lines.append(f"  {'':18} {'':12} gait: {default_gait_name(c)}")
    lines.append("Gaits (--gait NAME, or a .toml; default: the creature's gaits by speed):")
    for gait in builtin_gait_names():
        owner = gait_owner.get(gait)
        description = load_gait(gait, load_creature(owner)).description if owner else ""
        lines.append(f"  {gait:30} {owner or '':10} {description}")
    lines.append("Presets (--preset NAME, or a .json; the terrain and style ones passed tuning/data/matrix.json):")
    lines.extend(f"  {name:30} {creature:10} {what}" for name, creature, what in shipped_presets())
    _stdout().print("\n".join(lines), markup=False, soft_wrap=True, highlight=False)


def shipped_presets() -> list[tuple[str, str, str]]:
    """(name, creature, what it is for) of every shipped preset (``tuning/data/presets``): a creature's
    generic preset, or a terrain or style preset of ``tuning._matrix.PRESETS`` (read without JAX)."""
    from pathlib import Path

    from footfall.tuning import shipped_preset_paths
    from footfall.tuning._matrix import PRESETS

    rows = []
    for path in shipped_preset_paths():
        spec = PRESETS.get(path.stem)
        if spec is None:
            creature = json.loads(path.read_text())["creature"]
            rows.append((path.stem, creature, "generic: the gait timing fit to the stride law (flat ground, hills)"))
        elif "terrain" in spec:
            rows.append((path.stem, spec["creature"], f"terrain: {spec['terrain']}"))
        else:
            style = Path(spec["style"]).stem
            rows.append((path.stem, spec["creature"], f"style: {style} ({spec['style']}) on {', '.join(spec['terrains'])}"))
    return rows


@app.command("check")
def check_cmd(
    file: str = typer.Argument(..., help="A scenario, creature or gait: built-in name or path to a .toml (the kind "
                               "is told by the file's keys)"),
    creature: Optional[str] = typer.Option(None, help="Creature name or .toml to check a gait against (needed for a "
                                           "gait)"),
    speed: Optional[float] = typer.Option(None, help="Speed in m/s for a gait's duty-factor note (default: the "
                                          "scenario's, 0.3 for a gait file)"),
) -> None:
    """Load and validate a scenario, creature or gait file.

    A problem is one line naming the file, the field and the reason, with exit code 2; warnings \
(e.g. legs whose rest feet could cross) go to stderr with exit code 0.
    """
    from footfall.scenarios._gait_choice import duty_factor_note, resolve_gait
    from footfall.scenarios import load_creature, load_gait, load_scenario
    from footfall.scenarios._creatures import leg_crossing_warnings
    from footfall.scenarios._files import file_kind
    from footfall.scenarios._gaits import min_stance_feet

    if speed is not None and not (math.isfinite(speed) and speed > 0):
        raise InputError("argument", "--speed", f"expected a positive number of m/s, got {speed}")
    kind = file_kind(file)
    if creature is not None and kind != "gait":
        raise InputError("argument", "--creature", f"only a gait is checked against a creature; {file} is a {kind}")
    notes: list[str] = []
    warnings: list[str] = []
    if kind == "scenario":
        s = load_scenario(file)
        c = load_creature(s.crowd.creature)
        g, label, authored = resolve_gait(s, c)
        where = s.source
        line = (f"{s.source}: ok: scenario {s.name}, {len(s.obstacles)} obstacles, {s.crowd.count} x {c.name} "
                f"({c.n_legs} legs), gait {g.name}")
        if authored:
            notes.append(duty_factor_note(g, label, c, speed or s.crowd.speed))
    elif kind == "creature":
        c = load_creature(file)
        g, _, _ = resolve_gait(None, c, "default")
        where = file
        line = (f"{file}: ok: creature {c.name}, {c.n_legs} legs x {c.n_segments} segments, reach "
                f"{c.max_reach:.3g} m, rest radius {c.rest_radius:.3g} m ({scoring_scales_note(c.rest_radius)}); "
                f"default gait {g.name}: {g.description}")
        kind_of_note, text = speed_cap_note(c)
        (warnings if kind_of_note == "warning" else notes).append(text)
    else:
        if creature is None:
            raise InputError("argument", "--creature", f"a gait is checked against a creature: footfall check {file} "
                             "--creature NAME|FILE")
        c = load_creature(creature)
        g = load_gait(file, c)
        least, _ = min_stance_feet(g.swing_start, g.swing_duration)
        where = file
        line = (f"{file}: ok: gait {g.name} for {c.name} ({c.n_legs} legs), authored duty factor "
                f"{g.duty_factor:.2f}, at least {least} feet in stance")
        notes.append(duty_factor_note(g, file, c, speed or 0.3))
    _stdout().print(line, markup=False, soft_wrap=True)
    err = _err()
    for message in leg_crossing_warnings(c):
        err.print(f"footfall: warning: {where}: {c.name}: {message}", markup=False, soft_wrap=True)
    for message in warnings:
        err.print(f"footfall: warning: {where}: {message}", markup=False, soft_wrap=True)
    for note in filter(None, notes):
        err.print(f"footfall: note: {note}", markup=False, soft_wrap=True)


@app.command("plan")
def plan_cmd(
    scenario: str = typer.Argument("mixed", help="Built-in scenario name or path to a scenario .toml"),
    creature: Optional[str] = typer.Option(None, help="Creature name or .toml (default: the scenario's)"),
    budget: str = typer.Option("default", help="Search budget: first-valid, default or exhaustive"),
    step: Optional[float] = typer.Option(None, help="Step length in m (default: 0.4 x leg reach)"),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object"),
) -> None:
    """Plan one step of every foot of a creature standing at the scenario's spawn point."""
    import numpy as np

    from footfall.planner import WorldRaster, plan_foot, planner_config_for
    from footfall.planner._situations import stand, step_queries
    from footfall.scenarios import load_creature, load_scenario

    s = load_scenario(scenario)
    c = load_creature(creature or s.crowd.creature)
    search_budget = _budget(budget)
    if step is not None and not (math.isfinite(step) and step > 0):
        raise InputError("argument", "--step", f"expected a positive number of metres, got {step}")
    config = planner_config_for(c)
    raster = WorldRaster.build(s.terrain, s.obstacles, config.cell_size)
    standing = stand(c, raster, float(s.crowd.centre[0]), float(s.crowd.centre[1]), float(s.crowd.heading), 0.0, config)
    step_length = step if step is not None else 0.4 * float(c.max_reach)
    queries = step_queries(c, standing, step_length, 0.3 * float(c.standing_height))
    results = [plan_foot(standing.maps, q, budget=search_budget, config=config) for q in queries]
    if json_out:
        feet = []
        for leg, q, r in zip(c.leg_names, queries, results):
            feet.append({
                "leg": leg, "valid": r.valid, "source": q.source.tolist(), "target": r.target.tolist(),
                "slice_level_m": _finite(r.slice_level_m), "couple_score": r.couple_score,
                "footprint_score": r.footprint_score, "trajectory_score": r.trajectory_score,
                "breakdown": r.breakdown, "metrics": r.metrics, "counters": r.counters,
            })
        print(json.dumps({"scenario": s.name, "creature": c.name, "budget": budget, "step_length_m": step_length,
                          "feet": feet}))
        return
    table = Table(title=f"{c.name} on {s.name}: one step of {step_length:.3f} m, budget {budget}")
    for col in ("leg", "valid", "target (x, y, z) m", "slice", "couple", "footprint", "trajectory", "couples",
                "cells"):
        table.add_column(col, justify="right")
    for leg, r in zip(c.leg_names, results):
        level = "none" if not math.isfinite(r.slice_level_m) else f"{r.slice_level_m:.2f} m"
        table.add_row(leg, "yes" if r.valid else "hold", ", ".join(f"{v:.3f}" for v in r.target),
                      level if r.valid else "-", f"{r.couple_score:.3f}", f"{r.footprint_score:.3f}",
                      f"{r.trajectory_score:.3f}", str(r.counters["couples_evaluated"]),
                      str(r.counters["cells_expanded"]))
    _stdout().print(table)
    valid = int(np.sum([r.valid for r in results]))
    _stdout().print(f"{valid} of {len(results)} feet found a couple; the others hold.")


@app.command("simulate")
def simulate_cmd(
    scenario: str = typer.Argument("mixed", help="Built-in scenario name or path to a scenario .toml"),
    frames: int = typer.Option(300, min=1, help="Frames of 1/30 s"),
    characters: Optional[int] = typer.Option(None, min=1, help="Crowd size (default: the scenario's)"),
    creature: Optional[str] = typer.Option(None, help="Creature name or .toml (default: the scenario's)"),
    gait: Optional[str] = typer.Option(None, help="Gait name or .toml (default: the creature's)"),
    lod: str = typer.Option("off", help="Level of detail: on, zoomed or off"),
    seed: int = typer.Option(0, help="Seed (same seed, same recording)"),
    preset: Optional[str] = typer.Option(None, help="Weight preset for this creature: a .json file or a shipped "
                                         "one by name (spider, ant, ...)"),
    record: Optional[str] = typer.Option(None, help="Save the recording (.npz)"),
    navigate: bool = typer.Option(True, "--navigate/--no-navigate", help="Steer round static boxes and the loops "
                                  "of moving ones (docs/crowds.md: the way round static boxes); --no-navigate: ORCA and "
                                  "the box push alone, as before 2026-11-26"),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object"),
) -> None:
    """Simulate a crowd walking through a scenario and report what happened."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from footfall.cli._named_preset import load_named_preset
    from footfall.reports._runs import recorded_run, recording_meta
    from footfall.scenarios._gait_choice import resolve_gait, say_duty_factor
    from footfall.scenarios import load_creature, load_scenario

    s = load_scenario(scenario)
    c = load_creature(creature or s.crowd.creature)
    g, label, authored = resolve_gait(s if creature is None else None, c, gait)
    p = load_named_preset(preset, c.name) if preset is not None else None
    say_duty_factor(g, label, authored, c, s.crowd.speed, p.timing if p is not None else None)
    if record is not None and not record.endswith(".npz"):
        raise InputError("argument", "--record", f"expected a .npz path, got {record!r}")
    _check_lod(lod)
    with Progress(TextColumn("simulating"), BarColumn(), TextColumn("{task.completed}/{task.total} frames"),
                  TimeRemainingColumn(), console=_err(), transient=True,
                  disable=json_out or not _err().is_terminal) as bar:
        task = bar.add_task("frames", total=frames)
        model, summary, recorder = recorded_run(s, c, g, frames=frames, characters=characters, seed=seed, preset=p,
                                                lod=lod, record=record is not None, navigate=navigate,
                                                progress=lambda k: bar.update(task, completed=k))
    if record:
        recorder.save(record, model, summary, recording_meta(s, seed, lod, g, navigate))
    if json_out:
        print(json.dumps(summary.to_json()))
        return
    out = _stdout()
    table = Table(title=f"{summary.characters} x {c.name} on {s.name}, {frames} frames, LOD {lod}")
    table.add_column("metric")
    table.add_column("value", justify="right")
    for key, value in summary.to_json().items():
        if key == "stage_ms_median":
            value = ", ".join(f"{k} {v:.2f}" for k, v in value.items())
        elif isinstance(value, float):
            value = f"{value:.4g}"
        table.add_row(key, str(value))
    out.print(table)
    if record:
        out.print(f"recording: {record}")


@app.command("evaluate")
def evaluate_cmd(
    scenarios: Optional[list[str]] = typer.Argument(None, help="Scenarios (default: every built-in)"),
    creatures: Optional[str] = typer.Option(None, "--creatures", help="Comma-separated creature names or .toml files "
                                            "(default: every built-in)"),
    seeds: int = typer.Option(3, "--seeds", help="Seeds per scenario x creature"),
    seed_base: Optional[int] = typer.Option(None, "--seed-base", help="Seeds S, S+1, ... (default: fresh random "
                                            "seeds, printed)"),
    characters: int = typer.Option(6, "--characters", help="Crowd size of every run"),
    frames: int = typer.Option(300, "--frames", help="Frames of 1/30 s per run"),
    lod: str = typer.Option("off", "--lod", help="Level of detail: on, zoomed or off"),
    workers: Optional[int] = typer.Option(None, "--workers", help="Local worker processes (default: one per core; "
                                          "1: in-process)"),
    cluster: Optional[str] = typer.Option(None, "--cluster", help="Dask scheduler address (tcp://host:8786)"),
    out: Optional[str] = typer.Option(None, "--out", help="Folder for index.html, evaluate.json, runs.csv and "
                                      "pictures of the worst runs"),
    strict: bool = typer.Option(False, "--strict", help="Exit 1 when any promise is violated"),
    navigate: bool = typer.Option(True, "--navigate/--no-navigate", help="Every run steers round static boxes and "
                                  "the loops of moving ones (as simulate; --no-navigate: as simulate --no-navigate)"),
    preset: Optional[str] = typer.Option(None, "--preset", help="Walk every run with this preset (a shipped name or "
                                         "a .json file; it must be for every creature evaluated)"),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object"),
) -> None:
    """Check every promise on scenario x creature x seed runs; list the violations.

    Promises: collisions, crossings, overlaps, slip, IK, stuck, strides, speed. Prints a table of \
violations and the exact command that replays each of the worst runs.
    """
    from pathlib import Path

    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from footfall._distribute import check_workers
    from footfall.reports._evaluate import draw_seeds, evaluate, picture_png, run_one, table_rows, write_outputs
    from footfall.scenarios import builtin_creature_names, builtin_scenario_names, load_creature, load_scenario

    for option, value in (("--seeds", seeds), ("--characters", characters), ("--frames", frames)):
        if value < 1:
            raise InputError("argument", option, f"expected an integer >= 1, got {value}")
    _check_lod(lod)
    check_workers(workers, cluster)
    names = list(scenarios or builtin_scenario_names())
    kinds = [c.strip() for c in creatures.split(",")] if creatures else list(builtin_creature_names())
    if any(not c for c in kinds):
        raise InputError("argument", "--creatures", f"expected comma-separated names, got {creatures!r}")
    for name in names:
        load_scenario(name)  # bad input fails here, in one line, before any run
    creature_names = [load_creature(name).name for name in kinds]
    walk_with = None
    if preset is not None:
        from footfall.cli._named_preset import load_named_preset

        for name in creature_names:  # a preset is one creature's: checked against each before any run
            walk_with = load_named_preset(preset, name)
    drawn = draw_seeds(seeds, seed_base)
    err = _err()
    err.print(f"seeds: {', '.join(map(str, drawn))}", markup=False)
    total = len(names) * len(kinds) * len(drawn)
    with Progress(TextColumn("evaluate"), BarColumn(), TextColumn("{task.completed}/{task.total} runs"),
                  TimeElapsedColumn(), console=err, transient=True, disable=not err.is_terminal) as bar:
        task = bar.add_task("runs", total=total)
        result = evaluate(names, kinds, drawn, characters=characters, frames=frames, lod=lod, workers=workers,
                          cluster=cluster, progress=lambda _t, done: bar.update(task, completed=done),
                          navigate=navigate, preset=walk_with, preset_name=preset)
    if out is not None:
        pictures = {}
        for k, run in enumerate(result["failed_runs"][:3]):
            again = next(r for r in result["_runs"] if all(r[k] == run[k] for k in ("scenario", "creature", "seed")))
            pictures[f"worst-{k}.png"] = picture_png(run_one({**again, "picture": True}))
        write_outputs(Path(out), result, pictures)
    public = {k: v for k, v in result.items() if not k.startswith("_")}
    if json_out:
        print(json.dumps(public))
    else:
        columns, rows = table_rows(result)
        table = Table(title=f"Violations: {result['runs']} runs, {result['character_frames']} character-frames, "
                            f"{result['wall_s']:.0f} s")
        for col in columns:
            table.add_column(col, justify="left" if col in ("scenario", "creature") else "right")
        for row in rows:
            table.add_row(*row)
        console = _stdout()
        console.print(table)
        for run in result["failed_runs"][:5]:
            console.print(f"{sum(run['violations'].values())} violations: {run['replay']}", markup=False,
                          soft_wrap=True)
        if out is not None:
            console.print(f"report: {Path(out) / 'index.html'}")
    if strict and result["failed_runs"]:
        raise typer.Exit(1)


@app.command("run")
def run_cmd(
    scenario: str = typer.Argument("mixed", help="Built-in scenario name or path to a scenario .toml"),
    out: str = typer.Option("out", "--out", help="Output folder"),
    seed: int = typer.Option(0, help="Seed of every step (same seed, same results; timings aside)"),
    quick: bool = typer.Option(False, "--quick", help="Short runs, one tuning round and a quick sweep: a smoke "
                               "test of the pipeline, not a preset to ship (40-50 s on 2 cores once the kernels "
                               "are compiled, mostly the tune; a first run compiles them, a few minutes more)"),
    workers: Optional[int] = typer.Option(None, help="Local worker processes of the tune and the report (default: one "
                                          "per core; 1: in-process)"),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object"),
) -> None:
    """The main job: simulate the scenario's crowd, tune its creature, report, and export a USD scene.

    Progress goes to stderr: a live line on a terminal, else one line every few seconds with the \
step and the elapsed time.
    """
    from footfall.cli._mainjob import STEPS, run_main_job
    from footfall.cli._progress import Progress

    with Progress("footfall run", enabled=not json_out) as bar:

        def progress(step: str, message: str) -> None:
            bar.update(f"[{STEPS.index(step) + 1}/{len(STEPS)}] {step}: {message}", step=step)

        summary = run_main_job(scenario, out, seed=seed, quick=quick, workers=workers, progress=progress)
    if json_out:
        print(json.dumps(summary))
        return
    o, sec = summary["outputs"], summary["seconds"]
    tune = summary["tune"]
    lines = [
        f"footfall run: {summary['scenario']} ({summary['creature']}), {sec['total']:.0f} s",
        f"  simulate  {sec['simulate']:6.1f} s  {o['recording']}  ({summary['simulate']['steps']} steps, "
        f"{summary['simulate']['collisions']} collisions)",
        f"  tune      {sec['tune']:6.1f} s  {o['preset']}  (exact loss {tune.get('exact_loss_default', float('nan')):.3g}"
        f" -> {tune.get('exact_loss_tuned', float('nan')):.3g})",
        f"  report    {sec['report']:6.1f} s  {o['report']}  (recommended budget: "
        f"{summary['report']['recommended_budget']})",
        f"  export    {sec['export']:6.1f} s  {o['usd']}",
        f"  clip      {o['clip'] or 'not rendered: ' + str(summary['clip'].get('error'))}",
        f"  summary   {o['summary']}",
        f"Open {o['report']} in a browser to look at the results.",
    ]
    _stdout().print("\n".join(lines), markup=False, soft_wrap=True)


@app.command("export-usd")
def export_usd_cmd(
    scenario: Optional[str] = typer.Argument(None, help="Built-in scenario name or path to a scenario .toml "
                                             "(default: mixed, or the recording's)"),
    out: str = typer.Option(..., "--out", help="Output file: .usda (text), .usdc or .usd (binary)"),
    frames: Optional[int] = typer.Option(None, min=1, help="Frames of 1/30 s (default 90; with --recording: "
                                         "export the first N)"),
    characters: Optional[int] = typer.Option(None, min=1, help="Crowd size (default: the scenario's)"),
    creature: Optional[str] = typer.Option(None, help="Creature name or .toml (default: the scenario's, or the "
                                           "recording's)"),
    gait: Optional[str] = typer.Option(None, help="Gait name or .toml (default: the creature's)"),
    seed: Optional[int] = typer.Option(None, help="Seed (default 0; same seed, same animation)"),
    preset: Optional[str] = typer.Option(None, help="Weight preset for this creature: a .json file or a shipped "
                                         "one by name (spider, ant, ...)"),
    recording: Optional[str] = typer.Option(None, help="Export this recording (.npz from simulate --record) "
                                            "instead of simulating"),
) -> None:
    """Write a crowd run (simulated, or a recording) as a USD scene.

    The scene holds the terrain, the boxes, the skinned characters, the foot trajectories and the \
footprints. The crowd is the scenario's (its size unless --characters).
    """
    import tempfile
    from pathlib import Path

    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from footfall.reports._recording import load_recording
    from footfall.reports._usd import check_output_path, export_usd
    from footfall.scenarios import load_creature, load_scenario

    out_path = check_output_path(out)
    if recording is not None:
        given = [name for name, value in (("--characters", characters), ("--gait", gait), ("--seed", seed),
                                          ("--preset", preset)) if value is not None]
        if given:
            raise InputError("argument", "--recording", f"exports a finished run: {', '.join(given)} "
                             "cannot change it")
        run = load_recording(recording)
        s = load_scenario(scenario or run.scenario or "mixed")
        c = load_creature(creature) if creature else run.load_creature()
        if frames is not None:
            run = run.head(frames)
    else:
        from footfall.cli._named_preset import load_named_preset
        from footfall.reports._runs import recorded_run, recording_meta
        from footfall.scenarios._gait_choice import resolve_gait, say_duty_factor

        frames = frames or 90
        seed = seed or 0
        s = load_scenario(scenario or "mixed")
        c = load_creature(creature or s.crowd.creature)
        g, label, authored = resolve_gait(s if creature is None else None, c, gait)
        p = load_named_preset(preset, c.name) if preset is not None else None
        say_duty_factor(g, label, authored, c, s.crowd.speed, p.timing if p is not None else None)
        with Progress(TextColumn("simulating"), BarColumn(), TextColumn("{task.completed}/{task.total} frames"),
                      TimeRemainingColumn(), console=_err(), transient=True, disable=not _err().is_terminal) as bar:
            task = bar.add_task("frames", total=frames)
            model, summary, recorder = recorded_run(s, c, g, frames=frames, characters=characters or s.crowd.count,
                                                    seed=seed,
                                                    preset=p, progress=lambda k: bar.update(task, completed=k))
        # Through the recording file, so a simulated export and the export of its recording are the same.
        with tempfile.TemporaryDirectory(prefix="footfall-usd-") as folder:
            path = Path(folder) / "run.npz"
            recorder.save(path, model, summary, recording_meta(s, seed, "off", g))
            run = load_recording(path)
    with Progress(TextColumn("writing USD"), BarColumn(), TextColumn("{task.completed}/{task.total} parts"),
                  console=_err(), transient=True, disable=not _err().is_terminal) as bar:
        task = bar.add_task("parts", total=2 + run.characters)
        written = export_usd(run, s, c, out_path, progress=lambda done, total: bar.update(task, completed=done))
    _stdout().print(f"USD: {written} ({run.characters} x {c.name} on {s.name}, {run.frames} frames)",
                    markup=False, soft_wrap=True)


@app.command("report")
def report_cmd(
    scenarios: Optional[list[str]] = typer.Argument(None, help="Scenarios to sweep (default: the preset's)"),
    out: str = typer.Option("out/report", "--out", help="Report folder (replaced atomically)"),
    quick: bool = typer.Option(False, "--quick", help="A small sweep (seconds; for tests)"),
    full: bool = typer.Option(False, "--full", help="Every built-in scenario, 21 budgets, up to 100 characters (long)"),
    seed: int = typer.Option(0, help="Seed of every run (same seed, same metrics; timings aside)"),
    recording: Optional[str] = typer.Option(None, help="Also render this recording (.npz from simulate --record)"),
    cluster: Optional[str] = typer.Option(None, help="Dask scheduler address (tcp://host:8786) to run the sweep on"),
    workers: Optional[int] = typer.Option(None, help="Local worker processes (default: one per core; 1: in-process)"),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object"),
) -> None:
    """Evaluation sweep (scenarios x LOD settings x crowd sizes): cost, quality, plots, renders, index.html."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from footfall.reports._report import build_report

    if quick and full:
        raise InputError("argument", "--quick/--full", "choose one of --quick and --full")
    preset = "quick" if quick else "full" if full else "default"
    err = _err()
    warnings: list[str] = []
    bar = Progress(TextColumn("report"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                   TextColumn("{task.description}"), TimeElapsedColumn(), console=err, transient=True,
                   disable=not err.is_terminal)
    shown = []  # the bar starts with the work, so that refused input prints its one line alone

    def progress(what: str, done: int, total: int) -> None:
        if not shown:
            bar.start()
            shown.append(bar.add_task(what, total=total))
        bar.update(shown[0], description=what, completed=done, total=total)

    try:
        summary = build_report(out, preset=preset, scenarios=tuple(scenarios or ()), seed=seed, recording=recording,
                               progress=progress, warn=warnings.append, workers=workers, cluster=cluster)
    finally:
        if shown:
            bar.stop()
    for message in warnings:
        err.print(f"footfall: warning: {message}", markup=False, soft_wrap=True)
    if json_out:
        print(json.dumps(summary))
        return
    table = Table(title=f"Quality vs cost ({summary['preset']}; cost = plan time / first valid couple's, "
                        "loss = % of the exhaustive couple score; budget-cK-sS as cK-sS)")
    for col in ("setting", "cost", "loss %", "own loss %", "ms/char", "collisions", "crossings", "front"):
        table.add_column(col, justify="right")

    def number(value, fmt):
        return "-" if value is None else format(value, fmt)

    for r in summary["rows"]:
        table.add_row(r["setting"].removeprefix("budget-") + (" *" if r["recommended"] else ""), number(r["paired_cost_vs_first_valid"], ".3f"),
                      number(r["paired_loss_pct"], ".3f"), f"{r['score_loss_pct']:.3f}", f"{r['ms_per_character']:.2f}",
                      str(r["collisions"]), str(r["leg_crossings"]), "yes" if r["on_front"] else "")
    out_console = _stdout()
    out_console.print(table)
    out_console.print(f"recommended budget: {summary['recommended_budget']} (*)")
    out_console.print(f"report: {summary['index']}")


def _field_values(items: Optional[list[str]], option: str) -> tuple[tuple[str, float], ...]:
    """("FIELD=VALUE", ...) -> ((field, value), ...); a malformed item is an InputError naming the option."""
    pairs = []
    for item in items or ():
        name, sep, value = item.partition("=")
        try:
            number = float(value)
        except ValueError:
            number = None
        if not sep or not name.strip() or number is None:
            raise InputError("argument", option, f"expected FIELD=NUMBER, got {item!r}")
        pairs.append((name.strip(), number))
    return tuple(pairs)


@app.command("tune")
def tune_cmd(
    creature: str = typer.Option(..., "--creature", help="Creature to tune: built-in name or .toml"),
    scenarios: Optional[str] = typer.Option(
        None, "--scenarios", help="Tune the scoring weights for these terrains, A,B,... (built-in names, files or "
        "variants such as stairs@terrain.rise=0.1,terrain.run=0.3, whose overrides stay with it); runs spawn "
        "along each route and meet its feature"),
    targets: Optional[str] = typer.Option(
        None, "--targets", help="Targets .toml: the stride law, duty-factor bands and a style (tuning/_targets.py "
        "and tuning/data/styles/ for examples); with it, the weights are tuned (on stairs, crates, hills, mixed "
        "unless --scenarios says)"),
    out: Optional[str] = typer.Option(None, "--out", help="Preset file (.json; default out/presets/NAME.json); "
                                      "the checkpoint is written beside it"),
    resume: bool = typer.Option(False, "--resume", help="Continue a killed run from its checkpoint"),
    rounds: Optional[int] = typer.Option(None, "--rounds", help="Outer rounds at most (harvest, fit, exact runs; "
                                         "default 2, 3 with --scenarios/--targets)"),
    seed: int = typer.Option(0, "--seed", help="Seed of the harvests and runs (same seed, same preset)"),
    start_timing: Optional[list[str]] = typer.Option(
        None, "--start-timing", help="Start the search from a mis-tuned gait timing, FIELD=VALUE of GaitTiming "
        "(repeatable, e.g. stride_coefficient=3.0); the summary adds the *_start figures"),
    characters: int = typer.Option(1, "--characters", min=1, help="With --scenarios/--targets: characters per run"),
    seeds: int = typer.Option(3, "--seeds", min=1, help="With --scenarios/--targets: crowd seeds per scenario and "
                              "spawn (the training and the held-out runs)"),
    frames: int = typer.Option(300, "--frames", min=60, help="With --scenarios/--targets: frames per run (each "
                               "scenario is run from spawns along its route)"),
    spearman_candidates: int = typer.Option(
        0, "--spearman-candidates", min=0, help="With --scenarios/--targets: validate the proxies on this many "
        "candidate presets (>= 20 for the issue's check; costs as many exact evaluations)"),
    cluster: Optional[str] = typer.Option(None, help="Dask scheduler address (tcp://host:8786) to run the harvests "
                                          "and exact runs on"),
    workers: Optional[int] = typer.Option(None, help="Local worker processes (default: one per core; 1: in-process)"),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object"),
) -> None:
    """Tune a creature against its targets and write a preset.

    Without --scenarios and --targets: the gait timing against the stride law on a sweep of speeds (the \
generic preset). With either: the scoring weights for those terrains and that style, on runs that \
meet the terrain, checked on held-out variants (a terrain or style preset).
    """
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from footfall._distribute import check_workers
    from footfall.tuning._tune import TuneConfig, check_creature, check_output, tune

    from footfall.scenarios import load_creature

    check_workers(workers, cluster)
    check_creature(creature)
    path = check_output(out or f"out/presets/{load_creature(creature).name}.json")
    if rounds is not None and rounds < 1:
        raise InputError("argument", "--rounds", f"expected an integer >= 1, got {rounds}")
    events = scenarios is not None or targets is not None
    if events:
        from footfall.tuning._targets import load_tune_targets
        from footfall.tuning._tune_events import DEFAULT_SCENARIOS, EventTuneConfig, check_scenarios, tune_events

        if start_timing:
            raise InputError("argument", "--start-timing", "tunes the timing; --scenarios/--targets tune the weights")
        load_tune_targets(targets, creature)  # a malformed file: one line, before any work
        names = check_scenarios(scenarios) if scenarios is not None else DEFAULT_SCENARIOS
        config = EventTuneConfig(creature, scenarios=names, targets_file=targets, seed=seed, characters=characters,
                                 frames=frames, seeds=tuple(range(seeds)),
                                 holdout_seeds=tuple(range(101, 101 + seeds)),
                                 **({} if rounds is None else {"rounds": rounds}))
    else:
        config = TuneConfig(creature, rounds=rounds or 2, seed=seed,
                            start_timing=_field_values(start_timing, "--start-timing"))
    bar = Progress(TextColumn("tune"), BarColumn(), TextColumn("{task.description}"), TimeElapsedColumn(),
                   console=_err(), transient=True, disable=not _err().is_terminal)
    with bar:
        task = bar.add_task("starting", total=config.rounds + 2)

        def said(what, done, total):
            bar.update(task, description=what, completed=done, total=total)

        if events:
            result = tune_events(config, path, resume=resume, workers=workers, cluster=cluster, progress=said,
                                 spearman_candidates=spearman_candidates)
        else:
            result = tune(config, path, resume=resume, workers=workers, cluster=cluster, progress=said)
    summary = dict(result.summary, wall_s=result.wall_s, preset=str(path))
    if json_out:
        print(json.dumps(summary))
        return
    table = Table(title=f"footfall tune {load_creature(creature).name}: default -> tuned")
    table.add_column("metric")
    table.add_column("value", justify="right")
    for key, value in summary.items():
        if key == "targets":
            value = f"{value['file']} (stride law {value['stride_length']['coefficient']:g} h Fr^" \
                    f"{value['stride_length']['exponent']:g}; style {value['style'] or 'none'})"
        table.add_row(key, f"{value:.4g}" if isinstance(value, float) else str(value))
    _stdout().print(table)


@bench_app.command("crowd")
def bench_crowd_cmd(
    characters: Optional[int] = typer.Option(None, min=1, help="One crowd size (default: 100, 1000, 3000 and 5000)"),
    frames: int = typer.Option(60, min=1, help="Measured frames per run"),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object"),
) -> None:
    """The paper's Table 1: ms per frame, maps preparation, CCD IK and FPS per LOD mode, measured
    interleaved (the modes share the machine's load), and LOD on / LOD off per crowd size."""
    from footfall.benchmarks.crowd_bench import SIZES, run

    sizes = (characters,) if characters else SIZES
    with _err().status("benchmarking crowds...") as status:
        result = run(sizes=sizes, frames=frames, progress=lambda m: status.update(f"benchmarking {m}"))
    if json_out:
        print(json.dumps(result))
        return
    out = _stdout()
    for n, modes in result.items():
        lo, hi = modes["ratio_on_off_ci"]
        table = Table(title=f"{n} spiders on {modes['scenario']} (median ms per frame; LOD on / off = "
                            f"{modes['ratio_on_off']:.2f}, 95 % CI {lo:.2f}-{hi:.2f})")
        for col in ("LOD", "total for characters", "95 % CI", "maps preparation", "planning", "IK",
                    "average FPS"):
            table.add_column(col, justify="right")
        for mode in ("on", "zoomed", "off"):
            row = modes[mode]
            table.add_row(mode, f"{row['ms_per_frame']:.2f}", "{:.1f}-{:.1f}".format(*row["ms_per_frame_ci"]),
                          f"{row['maps_ms']:.2f}", f"{row['plan_ms']:.2f}", f"{row['ik_ms']:.2f}", f"{row['fps']:.0f}")
        out.print(table)
    out.print("paper (2012, 100 spiders): LOD 26 ms, LOD zoomed 28 ms, no LOD 45 ms per frame")


@bench_app.command("tuning")
def bench_tuning_cmd(
    creature: str = typer.Option("spider", help="Built-in creature to tune"),
    max_evals: int = typer.Option(150, "--max-evals", min=1, help="CMA-ES budget of exact-planner evaluations"),
    rounds: int = typer.Option(2, min=1, help="Outer rounds of the optimistix tune at most"),
    seed: int = typer.Option(0, min=0, help="Seed of the tune and of CMA-ES"),
    scenarios: Optional[str] = typer.Option(None, "--scenarios", help="Compare on a terrain tune of the weights "
                                            "(A,B,...; footfall tune --scenarios) instead of the timing tune"),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object"),
) -> None:
    """Optimistix on the JAX proxies vs CMA-ES on the exact planner.

    Wall time and exact evaluations to reach the same exact loss.
    """
    from footfall.benchmarks.tuning_bench import run, run_events, table
    from footfall.tuning._tune import check_creature

    check_creature(creature)
    with _err().status("benchmarking the tuning...") as status:
        if scenarios is not None:
            from footfall.tuning._tune_events import check_scenarios

            result = run_events(creature, check_scenarios(scenarios), seed=seed, max_evals=max_evals,
                                rounds=max(rounds, 1), progress=lambda m: status.update(f"benchmarking: {m}"))
        else:
            result = run(creature, seed=seed, max_evals=max_evals, rounds=rounds,
                         progress=lambda m: status.update(f"benchmarking: {m}"))
    if json_out:
        print(json.dumps(result))
        return
    _stdout().print(table(result))


@bench_app.command("presets")
def bench_presets_cmd(
    presets_dir: str = typer.Option("tuning/data/presets", "--presets-dir", help="Folder of the presets NAME.json"),
    names: Optional[str] = typer.Option(None, "--presets", help="Presets to prove, A,B,... (default: every terrain "
                                        "and style preset of tuning._matrix.PRESETS); with --out an existing "
                                        "matrix keeps the others' entries"),
    runs: int = typer.Option(30, "--runs", min=2, help="Paired runs per preset x terrain cell"),
    out: Optional[str] = typer.Option(None, "--out", help="Write the matrix here (.json), e.g. tuning/data/matrix.json"),
    prune: bool = typer.Option(False, "--prune", help="Delete from --presets-dir the presets that do not pass (only "
                               "a passing preset ships)"),
    cluster: Optional[str] = typer.Option(None, help="Dask scheduler address to run the runs on"),
    workers: Optional[int] = typer.Option(None, help="Local worker processes (default: one per core; 1: in-process)"),
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object"),
) -> None:
    """The terrain and style presets against the defaults on held-out terrains: paired runs per cell.

    A terrain preset passes with a per-stride error >= 2 SE better on its terrain and <= 1 SE worse \
elsewhere; a style preset with its style metric >= 2 SE toward its bound; neither with more collisions.
    """
    from footfall._atomic import write_text_atomic
    from footfall._distribute import check_workers, task_runner
    from footfall.tuning._matrix import PRESETS, carry_pruned, run_matrix

    check_workers(workers, cluster)
    chosen = tuple(n.strip() for n in names.split(",") if n.strip()) if names else tuple(PRESETS)
    for name in chosen:
        if name not in PRESETS:
            raise InputError("argument", "--presets", f"unknown preset {name!r}; expected {', '.join(PRESETS)}")
    if out is not None and not out.endswith(".json"):
        raise InputError("argument", "--out", f"expected a .json path, got {out!r}")
    with _err().status("proving the presets...") as status, task_runner(workers, cluster) as map_tasks:
        matrix = run_matrix(presets_dir, chosen, runs=runs, map_tasks=map_tasks,
                            progress=lambda m: status.update(f"proving the presets: {m}"))
    if out is not None:
        from pathlib import Path

        if Path(out).exists():
            stored = json.loads(Path(out).read_text())
            matrix = carry_pruned(matrix, stored)  # a pruned preset keeps saying why
            same = all(stored.get(k) == matrix[k] for k in ("terrains", "runs_per_cell", "seed_base", "spawns"))
            if names and same:
                # Some presets re-proved: their entries replace those of the stored matrix (same terrains and runs).
                matrix = {**stored, "presets": {**stored["presets"], **matrix["presets"]}}
        write_text_atomic(out, json.dumps(matrix, indent=1, allow_nan=False) + "\n")
    if prune:
        from pathlib import Path

        for name, p in matrix["presets"].items():
            preset = Path(presets_dir) / f"{name}.json"
            # A stored entry may name a preset pruned by an earlier run: nothing to remove then.
            if p["found"] and not p["passes"] and preset.exists():
                preset.unlink()
                (Path(presets_dir) / f"{name}.json.checkpoint.json").unlink(missing_ok=True)
                _err().print(f"footfall: note: {name} does not pass; removed from {presets_dir}", markup=False)
    if json_out:
        print(json.dumps(matrix))
        return
    _stdout().print(matrix_table(matrix))


def matrix_table(matrix: dict) -> Table:
    """The preset x terrain matrix: per cell, the main (or style) metric's gain in SE, default -> preset."""
    terrains = list(matrix["terrains"])
    table = Table(title=f"presets vs defaults on held-out terrains ({matrix['runs_per_cell']} paired runs per cell; "
                  "gain in SE, > 0 = better)")
    table.add_column("preset")
    for t in terrains:
        table.add_column(t, justify="right")
    table.add_column("passes")
    for name, p in matrix["presets"].items():
        if not p["found"] or not p["cells"]:
            table.add_row(name, *["-"] * len(terrains), "no: " + p["why"][0][:120])
            continue
        row = []
        for t in terrains:
            cell = p["cells"][t]
            main = cell["main"]
            text = (f"{main['default']:.3f}->{main['preset']:.3f} ({main['gain_se']:+.1f})"
                    if main["default"] is not None and main["gain_se"] is not None else "-")
            for key, s in cell["style"].items():
                if s["gain_se"] is not None:
                    text += f"\n{s['metric']} {s['default']:.3g}->{s['preset']:.3g} ({s['gain_se']:+.1f})"
            row.append(text)
        table.add_row(name, *row, "yes" if p["passes"] else "no: " + p["why"][0][:120])
    return table


def speed_cap_note(creature) -> tuple[str, str]:
    """("note" or "warning", text): the fastest the creature's legs carry at the stride law (the default
    one, its own rest feet) and what sets it (``planner._workspace.speed_caps``, as ``init_crowd`` caps
    a crowd); a warning naming the legs when they carry no stance at all (the creature cannot walk):
    what ``footfall check`` says of a creature file."""
    import numpy as np

    from footfall.planner import GaitTiming, creature_walk
    from footfall.planner._workspace import speed_cap_why

    walk = creature_walk(creature, GaitTiming(), 0.0)  # its caps, whatever speed is asked
    caps, reason, windows = walk.caps, walk.cap_reason, walk.window
    if caps[reason] <= 0.0:
        stuck = [creature.leg_names[i] for i in np.flatnonzero(windows[:, 1] - windows[:, 0] <= 1e-9)]
        return "warning", (f"{creature.name} cannot walk: legs {', '.join(stuck)} carry no stance at its standing "
                           f"height (their stance windows are empty); it stands where it spawns")
    return "note", f"{creature.name} walks at most {caps[reason]:.3g} m/s, {speed_cap_why(reason)}"


def scoring_scales_note(rest_radius: float) -> str:
    """How the default scoring weights' metre scales fit a creature of ``rest_radius`` (m)
    (``planner.default_weights``): what ``footfall check`` says of a creature file."""
    from footfall.planner._weights import size_factor

    k = size_factor(rest_radius)
    if k < 1.0:
        return f"the scoring's metre scales x{k:.2f} of the spider's"
    return "the scoring's metre scales the spider's"


@bench_app.command("planner")
def bench_planner_cmd(
    json_out: bool = typer.Option(False, "--json", help="Print one JSON object"),
    poses: int = typer.Option(12, min=1, help="Seeded creature poses per scenario"),
    seed: int = typer.Option(0, help="Seed of the poses"),
    repeats: int = typer.Option(3, min=1, help="Runs per measurement (the best is kept)"),
) -> None:
    """Median microseconds per foot plan on crates and mixed, and the shared wavefront's speedup."""
    from footfall.benchmarks.planner_bench import run

    err = _err()
    with err.status("benchmarking the planner...") as status:
        result = run(n_poses=poses, seed=seed, repeats=repeats, progress=lambda m: status.update(f"benchmarking {m}"))
    if json_out:
        print(json.dumps(result))
        return
    table = Table(title="Planner: median microseconds per foot plan")
    table.add_column("scenario")
    for col in ("first valid", "default", "exhaustive"):
        table.add_column(col, justify="right")
    for name, row in result["scenarios"].items():
        table.add_row(name, f"{row['first_valid_us']:.1f}", f"{row['default_us']:.1f}", f"{row['exhaustive_us']:.1f}")
    out = _stdout()
    out.print(table)
    out.print(f"shared wavefront speedup: {result['speedup_vs_per_target']:.1f}x vs one wavefront per target, "
              f"{result['speedup_vs_skimage_mcp']:.1f}x vs scikit-image MCP_Geometric "
              f"({result['details']['wavefront_grids']} foot grids)")


def _option_name(param) -> str:
    """How the user wrote a parameter: its longest option string (``--frames``), or an argument's name."""
    opts = [o for o in getattr(param, "opts", ()) if o.startswith("-")]
    if opts:
        return max(opts, key=len)
    return str(getattr(param, "name", None) or "argument").upper()


def _sentence(message: str) -> str:
    """A library's message as the REASON part of an error line: one line, no capital, no full stop."""
    text = " ".join(str(message).split()).rstrip(".")
    return text[:1].lower() + text[1:]


def usage_error(error: click_exceptions.UsageError) -> InputError:
    """The :class:`InputError` (``argument: FIELD: REASON``) for a usage error of typer/click's parser.

    Typer validates option values with pydantic; its error, kept as the exception's cause, gives the
    reason in the words the scenario files use (``must be >= 1``) and the value given.
    """
    import difflib

    from pydantic import ValidationError

    if isinstance(error, click_exceptions.MissingParameter):
        return InputError("argument", _option_name(error.param), "required; see --help")
    if isinstance(error, click_exceptions.BadParameter):
        field = _option_name(error.param) if error.param is not None else "argument"
        cause = error.__cause__
        if isinstance(cause, ValidationError):
            from footfall.scenarios._schema import pydantic_reason

            first = cause.errors(include_url=False)[0]
            return InputError("argument", field, f"{pydantic_reason(first)}, got {first.get('input')}")
        return InputError("argument", field, _sentence(error.message))
    if isinstance(error, click_exceptions.NoSuchOption):
        hint = f"; did you mean {' or '.join(sorted(error.possibilities))}?" if error.possibilities else ""
        where = error.ctx.command_path if error.ctx is not None else "footfall"
        return InputError("argument", error.option_name, f"no such option of {where}{hint}")
    if isinstance(error, click_exceptions.BadOptionUsage):
        reason = _sentence(error.message).removeprefix(f"option {error.option_name!r} ")
        return InputError("argument", error.option_name, reason)
    ctx = error.ctx
    where = ctx.command_path if ctx is not None else "footfall"
    if ctx is not None and isinstance(ctx.command, typer.core.TyperGroup) and error.message.startswith("No such command"):
        name = error.message.split("'")[1] if "'" in error.message else ""
        commands = ctx.command.list_commands(ctx)
        close = difflib.get_close_matches(name, commands, n=1)
        hint = f"did you mean {close[0]}?" if close else f"commands are: {', '.join(commands)}"
        return InputError("argument", name or "COMMAND", f"no such command of {where}; {hint}")
    if error.message.startswith("Got unexpected extra argument"):
        extra = error.message.rpartition(" (")[2].rstrip(")")
        return InputError("argument", extra or where, f"unexpected extra argument of {where}")
    return InputError("argument", where, _sentence(error.message))


def _show_flags_as_flags(command) -> None:
    """Help lists an on/off option as ``--json``, not ``--json <bool>``: no value follows a flag.

    Typer's help shows every option's type; a flag's metavar, when set, replaces it. Applied to
    every command, the help option included (it is made on demand, so it is made here).
    """
    commands = [command]
    while commands:
        cmd = commands.pop()
        params = list(cmd.params)
        help_option = cmd.get_help_option(typer.Context(cmd))
        if help_option is not None:
            params.append(help_option)
        for param in params:
            if getattr(param, "is_flag", False) and param.metavar is None:
                param.metavar = ""
        commands.extend(getattr(cmd, "commands", {}).values())


def _fail(error: Exception | str, code: int = 2) -> None:
    """Print the one error line ``footfall: error: ...`` on stderr and exit with ``code``."""
    _err().print(f"footfall: error: {error}", markup=False, soft_wrap=True)
    sys.exit(code)


@app.command("render")
def render_cmd(
    scenario: Optional[str] = typer.Argument(None, help="Built-in scenario name or .toml to simulate and render "
                                             "(default: mixed; not with --recording)"),
    out: str = typer.Option(..., "--out", help="Output video: .mp4 (H.264) or .gif"),
    recording: Optional[str] = typer.Option(None, help="Render this recording (.npz from simulate --record) "
                                            "instead of simulating"),
    frames: Optional[int] = typer.Option(None, help="Frames of 1/30 s (default 90 simulated; with --recording: "
                                         "its first N, default all)"),
    camera: str = typer.Option("follow", help="follow (the view glides with the crowd) or fixed (one view of the "
                               "whole run)"),
    width: int = typer.Option(960, help="Video width, pixels"),
    height: int = typer.Option(540, help="Video height, pixels"),
) -> None:
    """Render a crowd walking into a video (.mp4 or .gif).

    Offscreen, in a subprocess: the creatures' bodies and legs from the IK joints, foot tracks,
    pelvis paths, footprints, boxes, terrain, a legend and a scale bar."""
    import tempfile
    from pathlib import Path

    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from footfall.reports._animation import (DEFAULT_SIMULATED_FRAMES, RenderError, check_clip_options, recording_clip_scene,
                                    render_clip)

    out_path = check_clip_options(out, frames, camera, width, height)
    if recording is not None and scenario is not None:
        raise InputError("argument", "--recording", f"renders a finished run: the scenario {scenario!r} cannot "
                         "change it")
    err = _err()
    quiet = not err.is_terminal  # a bar on a pipe or file only leaves blank lines behind
    try:
        with tempfile.TemporaryDirectory(prefix="footfall-render-") as folder:
            if recording is None:
                from footfall.reports._runs import recorded_run, recording_meta
                from footfall.scenarios._gait_choice import resolve_gait, say_duty_factor
                from footfall.scenarios import load_creature, load_scenario

                s = load_scenario(scenario or "mixed")
                c = load_creature(s.crowd.creature)
                g, label, authored = resolve_gait(s, c)
                say_duty_factor(g, label, authored, c, s.crowd.speed)
                n = frames or DEFAULT_SIMULATED_FRAMES
                with Progress(TextColumn("simulating"), BarColumn(), TextColumn("{task.completed}/{task.total} "
                              "frames"), TimeRemainingColumn(), console=err, transient=True, disable=quiet) as bar:
                    task = bar.add_task("frames", total=n)
                    model, summary, recorder = recorded_run(s, c, g, frames=n, progress=lambda k: bar.update(
                        task, completed=k))
                recording = str(Path(folder) / "run.npz")
                recorder.save(recording, model, summary, recording_meta(s, 0, "off", g))
                frames = None
            scene = recording_clip_scene(recording, frames)
            with Progress(TextColumn("rendering"), BarColumn(), TextColumn("{task.completed}/{task.total} frames"),
                          TimeRemainingColumn(), console=err, transient=True, disable=quiet) as bar:
                task = bar.add_task("frames", total=len(scene["pelvis"]))
                result = render_clip(scene, out_path, camera=camera, size=(width, height),
                                     progress=lambda k, total: bar.update(task, completed=k))
    except RenderError as e:
        err.print(f"footfall: error: {out_path}: render: {e}", markup=False, soft_wrap=True)
        raise typer.Exit(1) from None
    _stdout().print(f"video: {result['path']} ({result['frames']} frames, {result['seconds']:.2f} s at "
                    f"{result['fps']:g} fps, {width} x {height}, camera {camera})", markup=False, soft_wrap=True)


def main(argv: list[str] | None = None) -> None:
    """Run the command line.

    Bad input of any kind, from the option parser or from the commands, prints one line
    ``footfall: error: FILE: FIELD: REASON`` on stderr and exits with code 2 (the parser's own
    boxed messages are not used); ``footfall`` or ``footfall bench`` alone print their help.
    """
    from footfall import configure_numba_cache

    configure_numba_cache()  # before any command imports the planner's kernels
    command = typer.main.get_command(app)
    _show_flags_as_flags(command)
    try:
        code = command.main(args=argv, prog_name="footfall", standalone_mode=False)
    except click_exceptions.NoArgsIsHelpError:
        # A group called with nothing: typer printed its help while making this error (rich help
        # prints, then returns ""); the usage-error code, as before.
        sys.exit(2)
    except click_exceptions.UsageError as e:
        _fail(usage_error(e))
    except click_exceptions.ClickException as e:
        _fail(_sentence(e.format_message()), e.exit_code)
    except typer.Abort:
        _fail("aborted", 1)
    except InputError as e:
        _fail(e)
    except ValueError as e:
        # Argument validation in the libraries names the argument in its message.
        _fail(f"argument: {e}")
    sys.exit(code if isinstance(code, int) else 0)
