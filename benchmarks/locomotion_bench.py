"""``footfall bench locomotion``: what each creature realises per stride across its speed range.

For every creature x scenario x speed: one character walks ``frames`` frames from a fresh start
(default seed); the row is its :class:`planner.SimulationSummary`'s locomotion figures: speed
asked and reached, the speed cap, per-stride error median and p90 against the stride law, the
duty factor, the gaits used, IK residual p95, stance slip, leg crossings and holds.

Speeds are given as Froude numbers ``Fr = v^2 / (g h)`` of the creature's hip height h, so that
the same row means the same thing for a spider and a dog: by default Fr = 0.05, 0.2 and 0.5
(a slow walk, a walk, half the walk-run boundary). A character that reaches its goal within
the run is measured until it does (the summary leaves the stop out).
"""

from __future__ import annotations

import math

FROUDE = (0.05, 0.2, 0.5)
SCENARIOS = ("flat", "hills", "stairs")


def run(creatures=("spider", "ant", "quadruped", "robot5"), scenarios=SCENARIOS, froude=FROUDE, frames: int = 300,
        seed: int = 0, progress=None) -> list[dict]:
    """Rows (dicts) of the table; ``creatures`` are names or creature files."""
    # Imported here, not at the top: ``python -m`` configures numba's cache before the kernels load.
    from footfall.planner._crowd import init_crowd
    from footfall.planner._simulation import simulate
    from footfall.planner._timing import GRAVITY, hip_height
    from footfall.scenarios import load_creature, load_scenario
    from footfall.scenarios._gait_schedule import gait_schedule

    rows = []
    for name in creatures:
        creature = load_creature(name)
        h = hip_height(creature)
        for scenario_name in scenarios:
            for fr in froude:
                speed = math.sqrt(fr * GRAVITY * h)
                scenario = load_scenario(f"{scenario_name}@crowd.speed={speed:.4f}")
                model, state = init_crowd(scenario, creature, gait_schedule(creature), n_characters=1, seed=seed)
                s = simulate(model, state, frames)
                rows.append({
                    "creature": creature.name, "scenario": scenario_name, "froude": fr, "speed_asked": s.speed_asked,
                    "speed_reached": s.speed_reached, "speed_cap": s.speed_cap,
                    "stride_rel_error_median": s.stride_rel_error_median, "stride_rel_error_p90": s.stride_rel_error_p90,
                    "strides": s.strides_measured, "duty_factor_mean": s.duty_factor_mean,
                    "gaits": {k: round(v, 3) for k, v in s.gait_fractions.items() if v > 0},
                    "ik_residual_p95_m": s.ik_residual_p95_m, "max_stance_slip_m": s.max_stance_slip_m,
                    "leg_crossings": s.leg_crossings, "holds": s.holds, "ms_per_frame_median": s.ms_per_frame_median,
                })
                if progress:
                    progress(f"{creature.name} on {scenario_name} at Fr {fr}")
    return rows


def markdown(rows: list[dict]) -> str:
    """The table as Markdown (the closing note's format)."""
    head = ("| creature | scenario | Fr | asked m/s | reached m/s | stride err median | p90 | duty factor | gaits | "
            "IK p95 mm | slip mm | crossings | holds |")
    lines = [head, "|" + "---|" * 13]

    def pct(x):
        return "–" if x is None else f"{100 * x:.1f} %"

    for r in rows:
        gaits = ", ".join(f"{k} {v:.0%}" for k, v in r["gaits"].items())
        lines.append(f"| {r['creature']} | {r['scenario']} | {r['froude']} | {r['speed_asked']:.3f} | "
                     f"{r['speed_reached']:.3f} | {pct(r['stride_rel_error_median'])} | {pct(r['stride_rel_error_p90'])} | "
                     f"{(r['duty_factor_mean'] or 0):.2f} | {gaits} | {1e3 * r['ik_residual_p95_m']:.2f} | "
                     f"{1e3 * r['max_stance_slip_m']:.2f} | {r['leg_crossings']} | {r['holds']} |")
    return "\n".join(lines)


if __name__ == "__main__":  # python -m footfall.benchmarks.locomotion_bench [creature ...]
    import sys

    from footfall import configure_numba_cache

    configure_numba_cache()
    print(markdown(run(creatures=tuple(sys.argv[1:]) or ("spider", "ant", "quadruped", "robot5"),
                       progress=lambda m: print(m, file=sys.stderr))))
