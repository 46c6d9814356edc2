"""Tuning of the scoring weights and the gait timing with JAX (issue 4).

* :mod:`tuning._scoring`: the runtime's goodnesses and scores, exactly, from the
  harvest's raw numbers (``footfall.tuning.harvest_situations``).
* :mod:`tuning._proxies`: a soft selection (temperature tau) over the harvested
  couples: expected step length, curvature energy, clearance, climb, jerk as
  smooth functions of the weights and of the gait-timing parameters.
* :mod:`tuning._targets`: biomechanics targets with their citations
  (``tuning/data/targets.toml``), per creature, normalised by its leg length.
* :mod:`tuning._fit`: Levenberg-Marquardt (optimistix) on the target residuals,
  log-parametrised weights and timing, the steps as one ``lax.scan``.
* :mod:`tuning._exact`: the exact loss -- the real crowd over a speed sweep, realised
  stride length vs the targets' law, duty factor, curvature energy, clearance, collisions.
* :mod:`tuning._tune`: the outer loop (harvest -> fit -> exact loss, checkpoint after
  every round, resume), held-out evaluation and the preset (``footfall tune``). Shipped
  presets: ``tuning/data/presets/<creature>.json`` (:data:`PRESETS_DIR`).
* :mod:`tuning._events`, :mod:`tuning._tune_events`: the terrain and style tunes of the scoring
  weights (``footfall tune --scenarios ... --targets ...``, issue 18): runs that meet the terrain,
  per-event metrics, the weights' fit blocks, held-out variants.
* :mod:`tuning._validate`: the proxies' predicted metric changes against the exact runs' (Spearman).
* :mod:`tuning._matrix`: the terrain and style presets' proof, a preset x terrain matrix on held-out
  runs (``footfall bench presets``, ``tuning/data/matrix.json``).

tuning/ computes in float64: its entry points call :func:`enable_x64`.
"""

from importlib import import_module
from pathlib import Path

PRESETS_DIR = Path(__file__).resolve().parent / "data" / "presets"
"""The shipped, tuned presets (``footfall simulate --preset spider`` or ``--preset FILE``)."""


def shipped_preset_paths() -> list[Path]:
    """The preset files in :data:`PRESETS_DIR`, by name: every ``*.json`` but a tune's checkpoints
    (``NAME.json.checkpoint.json``, written beside a preset tuned into that folder).

    Returns
    -------
    list of Path
        Sorted by file name.

    Examples
    --------
    >>> from footfall.tuning import shipped_preset_paths
    >>> names = [path.stem for path in shipped_preset_paths()]
    >>> {"spider", "quadruped", "quadruped-stairs"} <= set(names)
    True
    >>> any(name.endswith(".checkpoint") for name in names)
    False
    """
    return sorted(p for p in PRESETS_DIR.glob("*.json") if not p.name.endswith(".checkpoint.json"))


# Lazy re-exports (PEP 562): ``import tuning`` and the JAX-free modules (``tuning._targets``)
# must not load JAX, so that the report and the CLI can read the targets and the shipped
# presets without it. A name is imported from its module on first use.
_EXPORTS = {
    "enable_x64": "_config",
    "creature_defaults": "_defaults",
    **dict.fromkeys(("FITTED_TIMING", "FitProblem", "fit", "loss", "make_problem", "residuals"), "_fit"),
    **dict.fromkeys(("PROXY_METRICS", "Situations", "couple_scores", "duty_factor", "expected_metrics",
                     "hard_metrics", "preferred_footprint", "preferred_lead_time", "situations_from_harvest",
                     "soft_selection", "stride_frequency", "stride_length"), "_proxies"),
    **dict.fromkeys(("harvest_chunk", "harvest_situations", "harvest_tasks"), "_harvest_runs"),
    **dict.fromkeys(("QUANTITIES", "TARGETS_FILE", "CreatureTargets", "Target", "load_targets"), "_targets"),
    **dict.fromkeys(("couple_score", "couple_terms", "footprint_goodness", "footprint_score", "trajectory_goodness",
                     "trajectory_score", "weighted_mean"), "_scoring"),
}


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))


__all__ = ["PRESETS_DIR", "shipped_preset_paths", *_EXPORTS]
