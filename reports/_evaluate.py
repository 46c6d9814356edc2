"""``footfall evaluate``: every promise checked on runs nobody tuned for (issue 14, item 4).

Runs scenario x creature x seed, each one simulation exactly as ``footfall simulate SCENARIO
--creature C --seed S --characters N --frames F --lod MODE`` would run it, and counts, per run, the
violations of every promise in :data:`PROMISES`. The promises, their thresholds and their
descriptions live in that one table: the printed table, the JSON and the HTML page read it.

The runs are tasks of :func:`footfall._distribute.run_tasks` (in-process, local worker
processes, or a Dask cluster), gathered in task order, so the result does not depend on the
workers.
"""

from __future__ import annotations

import csv
import html
import io
import math
import secrets
import shlex
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

SLIP_LIMIT_M = 1e-3
IK_LIMIT_M = 2e-3
SPEED_FRACTION = 0.95


@dataclass(frozen=True)
class Promise:
    """One promise: ``count(summary, scenario_name)`` is the number of its violations in a run."""

    name: str
    description: str
    count: Callable[[dict, str], int]


def _counter(field: str) -> Callable[[dict, str], int]:
    return lambda s, _name: int(s.get(field, 0) or 0)


def _stride_error(s: dict, name: str) -> int:
    # Issue 13's bars: flat ground median <= 5 %, p90 <= 15 %; elsewhere 10 % and 25 %.
    if (s.get("strides_measured") or 0) < 3 or s.get("stride_rel_error_median") is None:
        return 0
    median_max, p90_max = (0.05, 0.15) if _is_flat(name) else (0.10, 0.25)
    return int(s["stride_rel_error_median"] > median_max or s["stride_rel_error_p90"] > p90_max)


def _speed(s: dict, name: str) -> int:
    if not _is_flat(name):
        return 0
    goal = min(s["speed_asked"], s["speed_cap"] if s.get("speed_cap") is not None else math.inf)
    return int(s["speed_reached"] < SPEED_FRACTION * goal)


def _is_flat(name: str) -> bool:
    return name.split("@")[0].startswith("flat")


PROMISES: tuple[Promise, ...] = (
    Promise("collisions", "rendered feet inside a box (foot-frames)", _counter("collisions")),
    Promise("forbidden_footprints", "landings on a forbidden box", _counter("forbidden_footprints")),
    Promise("leg_crossings", "pairs of a character's legs whose ground projections cross (frames)",
            _counter("leg_crossings")),
    Promise("body_overlaps", "pairs of characters whose body boxes overlap (frames)", _counter("body_overlaps")),
    Promise("shared_foot_spots", "stance feet of two characters closer than a foot length (frames)",
            _counter("shared_foot_spots")),
    Promise("unavoidable_contacts", "feet inside a box faster than the creature (no escape)",
            _counter("unavoidable_contacts")),
    Promise("stance_slip", f"a stance foot moved more than {SLIP_LIMIT_M * 1e3:g} mm from its touch-down (runs)",
            lambda s, _n: int(s["max_stance_slip_m"] > SLIP_LIMIT_M)),
    Promise("ik_residual", f"IK residual p95 above {IK_LIMIT_M * 1e3:g} mm (runs)",
            lambda s, _n: int(s["ik_residual_p95_m"] > IK_LIMIT_M)),
    Promise("stuck", "character-seconds under 10 % of the asked speed over 2 s, goal not reached (s, rounded up)",
            lambda s, _n: int(math.ceil(s.get("stuck_seconds", 0.0) - 1e-9))),
    Promise("stride_error", "per-stride error above the bars (flat: median 5 %, p90 15 %; else 10 %, 25 %) (runs)",
            _stride_error),
    Promise("speed_reached", f"on flat ground, under {SPEED_FRACTION:.0%} of min(asked, cap) (runs)", _speed),
)
PROMISE_NAMES = tuple(p.name for p in PROMISES)


def violations(summary: dict, scenario: str) -> dict[str, int]:
    """{promise: count} for one run's summary (``SimulationSummary.to_json()``).

    >>> s = dict(collisions=0, forbidden_footprints=0, leg_crossings=2, body_overlaps=0, shared_foot_spots=0,
    ...          max_stance_slip_m=0.001, ik_residual_p95_m=0.0, stuck_seconds=0.0, strides_measured=0,
    ...          stride_rel_error_median=None, stride_rel_error_p90=None, speed_asked=0.3, speed_cap=None,
    ...          speed_reached=0.3)
    >>> {k: v for k, v in violations(s, "crates").items() if v}
    {'leg_crossings': 2}
    """
    return {p.name: p.count(summary, scenario) for p in PROMISES}


def replay_command(run: dict) -> str:
    preset = run.get("preset")
    return (f"footfall simulate {run['scenario']} --creature {run['creature']} --seed {run['seed']} "
            f"--characters {run['characters']} --frames {run['frames']} --lod {run['lod']}"
            f"{'' if run.get('navigate', True) else ' --no-navigate'}"
            f"{'' if preset is None else f' --preset {shlex.quote(preset)}'} --json")


def run_one(task: dict) -> dict:
    """One run (a task of :func:`footfall._distribute.run_tasks`): its summary and violations; with
    ``task['picture']``, also the pelvis paths and footprints for a picture."""
    from footfall.reports._runs import recorded_run, speed_cap_message
    from footfall.scenarios._gait_choice import resolve_gait
    from footfall.scenarios import load_creature, load_scenario

    scenario = load_scenario(task["scenario"])
    creature = load_creature(task["creature"])
    own = task["creature"] == scenario.crowd.creature
    gait, _, _ = resolve_gait(scenario if own else None, creature)
    navigate = bool(task.get("navigate", True))
    preset = None
    if task.get("weights") is not None:  # the preset travels as numbers: a worker need not have its file
        from footfall.planner import GaitTiming, Preset, ScoringWeights

        timing = None if task.get("timing") is None else GaitTiming.from_array(task["timing"])
        preset = Preset(creature.name, ScoringWeights.from_array(task["weights"]), timing, None, {})
    model, summary, recorder = recorded_run(scenario, creature, gait, frames=task["frames"],
                                            characters=task["characters"], seed=task["seed"], lod=task["lod"],
                                            navigate=navigate, record=bool(task.get("picture")), preset=preset,
                                            say_cap=False)
    s = summary.to_json()
    out = {**{k: task[k] for k in ("scenario", "creature", "seed", "characters", "frames", "lod")},
           "navigate": navigate, **{k: task.get(k) for k in ("preset", "weights", "timing")},
           "summary": s, "violations": violations(s, task["scenario"]), "speed_cap_note": speed_cap_message(model)}
    if recorder is not None:
        a = recorder.arrays
        landed = a["in_stance"][1:] & ~a["in_stance"][:-1]
        obs = model.raster.obstacles
        centres, yaws = obs.poses_at(task["frames"] * model.dt)
        out["picture"] = {"pelvis": a["pelvis"][:, :, [0, 2]].tolist(),
                          "footprints": a["feet"][1:][landed][:, [0, 2]].tolist(),
                          "boxes": [[float(c[0]), float(c[2]), float(z[0]), float(z[2]), float(y), bool(f)]
                                    for c, z, y, f in zip(centres, obs.sizes, yaws, obs.forbidden)]}
    return out


def draw_seeds(seeds: int, seed_base: int | None) -> list[int]:
    """The seeds of the runs: ``seed_base, seed_base + 1, ...`` or fresh ones from the OS."""
    if seed_base is not None:
        return [seed_base + k for k in range(seeds)]
    return [secrets.randbits(31) for _ in range(seeds)]


def evaluate(scenarios, creatures, seeds: list[int], *, characters: int, frames: int, lod: str,
             workers: int | None = None, cluster: str | None = None, progress=None, navigate: bool = True,
             preset=None, preset_name: str | None = None) -> dict:
    """Run every scenario x creature x seed; the ``--json`` result plus the runs. ``navigate``:
    ``ControllerConfig.navigate`` for every run. ``preset``: a :class:`planner.Preset` every run walks
    with (its weights and timing; the caller has checked it is for every creature), ``preset_name`` what
    it was given as (``--preset``, repeated in the replay commands)."""
    from footfall._distribute import run_tasks

    t0 = time.perf_counter()
    numbers = {"preset": None, "weights": None, "timing": None}
    if preset is not None:
        numbers = {"preset": preset_name, "weights": [float(x) for x in preset.weights.to_array()],
                   "timing": None if preset.timing is None else [float(x) for x in preset.timing.to_array()]}
    tasks = [{"scenario": sc, "creature": cr, "seed": int(seed), "characters": characters, "frames": frames,
              "lod": lod, "navigate": navigate, **numbers}
             for sc in scenarios for cr in creatures for seed in seeds]
    runs = run_tasks(run_one, tasks, workers=workers, cluster=cluster, progress=progress)
    # Each creature's speed cap said once (its runs say the same: a note per run was 18 lines a creature).
    for note in dict.fromkeys(run["speed_cap_note"] for run in runs if run.get("speed_cap_note")):
        print(note, file=sys.stderr)
    totals = {name: 0 for name in PROMISE_NAMES}
    failed = []
    for run in runs:
        for name, n in run["violations"].items():
            totals[name] += n
        bad = {k: v for k, v in run["violations"].items() if v}
        if bad:
            failed.append({"scenario": run["scenario"], "creature": run["creature"], "seed": run["seed"],
                           "violations": bad, "replay": replay_command(run)})
    failed.sort(key=lambda r: -sum(r["violations"].values()))
    return {"runs": len(runs), "character_frames": int(sum(r["characters"] * r["frames"] for r in runs)),
            "violations": totals, "failed_runs": failed, "wall_s": time.perf_counter() - t0, "_runs": runs}


def table_rows(result: dict) -> tuple[list[str], list[list[str]]]:
    """(columns, rows) of violations per scenario x creature: promises with any violation, and a total."""
    shown = [name for name in PROMISE_NAMES if result["violations"][name]]
    cells: dict[tuple[str, str], dict[str, int]] = {}
    for run in result["_runs"]:
        cell = cells.setdefault((run["scenario"], run["creature"]), {name: 0 for name in PROMISE_NAMES})
        for name, n in run["violations"].items():
            cell[name] += n
    rows = [[sc, cr] + [str(cell[name]) for name in shown] + [str(sum(cell.values()))]
            for (sc, cr), cell in cells.items()]
    return ["scenario", "creature"] + shown + ["total"], rows


def write_outputs(out: Path, result: dict, pictures: dict[str, bytes]) -> None:
    """``out/index.html`` (the table, the worst runs with their replay commands and pictures),
    ``out/evaluate.json`` and ``out/runs.csv``, each written atomically. ``runs.csv`` has one row per run:
    its setting, each promise's violation count (named by the promise) and what the run measured (named
    by the summary's keys; the measured speed as ``speed_reached_m_s``, apart from the promise of that
    name)."""
    import json

    from footfall._atomic import atomic_path, write_text_atomic

    out.mkdir(parents=True, exist_ok=True)
    public = {k: v for k, v in result.items() if not k.startswith("_")}
    for name, data in pictures.items():
        with atomic_path(out / name) as tmp:
            tmp.write_bytes(data)
    write_text_atomic(out / "evaluate.json", json.dumps(public, indent=1))
    buf = io.StringIO()
    writer = csv.writer(buf)
    measured = ("max_stance_slip_m", "ik_residual_p95_m", "stride_rel_error_median", "stride_rel_error_p90",
                "speed_asked", "speed_reached", "stuck_seconds", "max_pelvis_jump_m", "box_shoves")
    # The measured speed shares its summary key with its promise: the column says its unit instead.
    header = ["speed_reached_m_s" if m == "speed_reached" else m for m in measured]
    writer.writerow(["scenario", "creature", "seed", "characters", "frames", "lod", *PROMISE_NAMES, *header])
    for run in result["_runs"]:
        writer.writerow([run["scenario"], run["creature"], run["seed"], run["characters"], run["frames"], run["lod"],
                         *(run["violations"][n] for n in PROMISE_NAMES), *(run["summary"].get(m) for m in measured)])
    write_text_atomic(out / "runs.csv", buf.getvalue())
    columns, rows = table_rows(result)
    head = "".join(f"<th>{html.escape(c)}</th>" for c in columns)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(v)}</td>" for v in row) + "</tr>" for row in rows)
    legend = "".join(f"<li><b>{p.name}</b>: {html.escape(p.description)}</li>" for p in PROMISES)
    worst = ""
    for k, run in enumerate(result["failed_runs"][:5]):
        picture = f"worst-{k}.png"
        img = f'<img src="{picture}" alt="top view of the run" width="600">' if picture in pictures else ""
        worst += (f"<h3>{html.escape(run['scenario'])} / {html.escape(run['creature'])} / seed {run['seed']}</h3>"
                  f"<p>{html.escape(str(run['violations']))}</p><pre>{html.escape(run['replay'])}</pre>{img}")
    page = (f"<!doctype html><html><head><meta charset='utf-8'><title>footfall evaluate</title></head><body>"
            f"<h1>footfall evaluate</h1><p>{result['runs']} runs, {result['character_frames']} character-frames, "
            f"{result['wall_s']:.1f} s.</p><table border='1'><tr>{head}</tr>{body}</table>"
            f"<h2>Promises</h2><ul>{legend}</ul><h2>Worst runs</h2>{worst or '<p>none</p>'}</body></html>")
    write_text_atomic(out / "index.html", page)


def picture_png(run: dict) -> bytes:
    """Top view of a run: boxes (forbidden red, safe orange), pelvis paths, footprints."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.patches import Polygon

    pic = run["picture"]
    fig, ax = plt.subplots(figsize=(7, 6))
    for x, z, sx, sz, yaw, forbidden in pic["boxes"]:
        c, s = math.cos(yaw), math.sin(yaw)
        corners = [(x + a * sx / 2 * c - b * sz / 2 * s, z + a * sx / 2 * s + b * sz / 2 * c)
                   for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        ax.add_patch(Polygon(corners, color="tab:red" if forbidden else "tab:orange", alpha=0.5))
    pelvis = np.asarray(pic["pelvis"])
    for c in range(pelvis.shape[1]):
        ax.plot(pelvis[:, c, 0], pelvis[:, c, 1], lw=1, label="pelvis paths" if c == 0 else None)
    feet = np.asarray(pic["footprints"]).reshape(-1, 2)
    ax.plot(feet[:, 0], feet[:, 1], ".", ms=2, color="k", label="footprints")
    lo, hi = pelvis.reshape(-1, 2).min(axis=0) - 1.0, pelvis.reshape(-1, 2).max(axis=0) + 1.0
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_title(f"{run['scenario']} / {run['creature']} / seed {run['seed']}: red forbidden, orange safe boxes")
    ax.legend(loc="upper right")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80)
    plt.close(fig)
    return buf.getvalue()
