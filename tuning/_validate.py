"""Validate the proxies where it counts: do they predict how the exact runs change? (issue 18, item 2)

``spearman_proxy_exact`` of the legacy tune ranks the JAX couple scores against the runtime's: 1 by
construction (the hard proxy is the runtime's formula), so it proves nothing about the fit. Here:

1. draw ``n`` candidate presets around the defaults: every one of the ten scoring weights times
   exp(N(0, :data:`LOG_SIGMA`)) (seed ``config.seed + 2000``; the reference scales kept);
2. **predicted change** of each metric: the soft expectation (:func:`tuning._proxies.expected_metrics`,
   temperature ``config.tau``) over the situations harvested once at the defaults on the tune's
   scenarios, candidate minus defaults, mean over the situations;
3. **exact change**: the tune's runs (:mod:`tuning._events`) under the candidate minus under the
   defaults, mean over the runs (paired: the same runs);
4. Spearman's rank correlation across the candidates, per metric of :data:`PAIRS` (proxy metric ->
   run metric, with the sign that relates them).

``spearman_min`` (the lowest over the metrics that vary) is the tune's ``spearman_metric_change``.
"""

from __future__ import annotations

import math

import numpy as np

LOG_SIGMA = 0.7
"""Spread of the candidates' log weights: a factor 2 either way, so that their exact changes stand
out of the runs' chaotic noise (a small change reshuffles every later footstep)."""
PAIRS = (
    ("offset_m", "stride_error", 1.0),
    ("touchdown_slope_rad", "touchdown_slope_rad", 1.0),
    ("touchdown_roughness_m", "touchdown_roughness_m", 1.0),
    ("touchdown_clearance_m", "clearance_p05_h", 1.0),
    ("curvature_energy", "curvature_p95", 1.0),
)
"""(proxy metric, run metric, sign): the run metric is expected to move as sign x the proxy's."""
UNMOVED = {"curvature_p95": 1e-9}
"""Run metrics whose changes below this are no change: a straight swing's curvature energy is 0 or
1e-27 (rounding), and ranking rounding noise says nothing about the proxies."""


def candidate_weights(n: int, seed: int, base: np.ndarray) -> list[np.ndarray]:
    """``n`` weight vectors (ScoringWeights.to_array()) around ``base``, the creature's defaults
    (module docstring)."""
    from footfall.planner.layout import N_TERMS

    rng = np.random.default_rng(seed)
    base = np.asarray(base, dtype=np.float64)
    out = []
    for _ in range(n):
        w = base.copy()
        w[:N_TERMS] *= np.exp(rng.normal(0.0, LOG_SIGMA, N_TERMS))
        out.append(w)
    return out


def metric_change_spearman(config, targets, n: int, map_tasks=None) -> dict:
    """Steps 1-4 of the module docstring for a :class:`tuning._tune_events.EventTuneConfig`."""
    import jax.numpy as jnp
    from scipy.stats import spearmanr

    from footfall.planner import ScoringWeights
    from footfall.tuning._config import enable_x64
    from footfall.tuning._defaults import creature_defaults
    from footfall.tuning._harvest_runs import harvest_situations
    from footfall.tuning._events import CLEARANCE_CAP_H, event_metrics, spawn_variant
    from footfall.tuning._proxies import compiled_expected_metrics, situations_from_harvest
    from footfall.tuning._tune_events import HARVEST_SPAWN

    enable_x64()
    if n < 3:
        raise ValueError(f"metric_change_spearman: expected at least 3 candidates, got {n}")
    timing = targets.timing()
    scenarios = tuple(spawn_variant(s, HARVEST_SPAWN) for s in config.scenarios)
    harvest = harvest_situations(scenarios=scenarios, creatures=(config.creature,), seeds=(config.seed + 1000,),
                                 frames=config.harvest_frames, n_characters=config.harvest_characters,
                                 timing=timing, max_situations=config.max_situations, map_tasks=map_tasks)
    situations = situations_from_harvest(harvest)
    cap = CLEARANCE_CAP_H * targets.leg_length_m
    t = jnp.asarray(timing.to_array())

    def proxy(w):
        m = compiled_expected_metrics(jnp.asarray(w), t, situations, config.tau, clearance_cap_m=cap,
                                      touchdown_cap_m=cap)
        return {k: float(jnp.mean(m[k])) for k, _, _ in PAIRS}

    setup = config.setup()
    defaults = creature_defaults(config.creature)
    default_w = defaults.to_array()
    p0 = proxy(default_w)
    e0 = event_metrics(setup, defaults, timing, targets, map_tasks)
    predicted = {k: [] for k, _, _ in PAIRS}
    measured = {k: [] for _, k, _ in PAIRS}
    candidates = candidate_weights(n, config.seed + 2000, default_w)
    for w in candidates:
        p = proxy(w)
        e = event_metrics(setup, ScoringWeights.from_array(w), timing, targets, map_tasks)
        for (pk, ek, sign) in PAIRS:
            predicted[pk].append(sign * (p[pk] - p0[pk]))
            measured[ek].append(_mean_change(e, e0, ek))
    rho = {}
    for pk, ek, _ in PAIRS:
        x, y = np.asarray(predicted[pk]), np.asarray(measured[ek])
        keep = np.isfinite(x) & np.isfinite(y)
        if keep.sum() < 3 or np.ptp(x[keep]) == 0.0 or np.abs(y[keep]).max() <= UNMOVED.get(ek, 0.0):
            rho[ek] = None  # a metric the candidates do not move (e.g. no curvature on stairs)
        else:
            rho[ek] = float(spearmanr(x[keep], y[keep]).statistic)
    values = [v for v in rho.values() if v is not None]
    return {"candidates": n, "log_sigma": LOG_SIGMA, "seed": config.seed + 2000, "runs_per_candidate": setup.n_runs,
            "rho": rho, "spearman_min": min(values) if values else None,
            "spearman_median": float(np.median(values)) if values else None,
            "predicted": {k: [float(v) for v in vs] for k, vs in predicted.items()},
            "measured": {k: [None if not math.isfinite(v) else float(v) for v in vs] for k, vs in measured.items()}}


def _mean_change(candidate: dict, default: dict, key: str) -> float:
    a = np.array([r[key] for r in candidate["runs"]], dtype=np.float64)
    b = np.array([r[key] for r in default["runs"]], dtype=np.float64)
    keep = np.isfinite(a) & np.isfinite(b)
    return float(np.mean(a[keep] - b[keep])) if keep.any() else math.nan
