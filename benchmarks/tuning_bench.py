"""``footfall bench tuning``: optimistix on the JAX proxies against CMA-ES on the exact planner.

For one creature, both methods minimise the **same exact loss** (:func:`tuning._exact.exact_metrics`
on ``TuneConfig.exact_setup()``, the same targets), over the same parameters, from the same start
(the default weights and ``TuneConfig.start()``: by default a mis-tuned timing, :data:`BENCH_SETUP`):

* **proxy** -- :func:`tuning._tune.tune` (harvest -> Levenberg-Marquardt fit on the proxies -> a
  line search on the exact loss, ``rounds`` at most). Its exact-planner evaluations are counted from
  the tune's checkpoint: 1 (the start parameters' exact loss) + every line-search entry of every
  round. Its result is the checkpoint's best (accepted) exact loss: the *target* (a line-search
  candidate refused may have had a lower one; it is counted, not used). The
  held-out evaluation and the Spearman harvest that end a tune measure the preset, they do not
  optimise it: the tune runs without them (``evaluate=False``), so they are neither run, counted
  nor timed. The wall time includes the harvests and the fits (with JAX tracing and compilation
  of the fit, which every ``footfall tune`` process pays once). Both methods run in this process
  (``workers=1``) on :data:`BENCH_SETUP`.
* **cmaes** -- a seeded ``cma.CMAEvolutionStrategy`` on x = log of the 19 ``ScoringWeights`` and log
  of the 4 ``tuning._fit.FITTED_TIMING`` fields (the space the fit searches; the other timing fields
  stay at the start's), x0 = log of the start, sigma0 = :data:`SIGMA0` (log space: a factor of
  about 1.35 per standard deviation). Every candidate asked is one exact-planner evaluation. It
  stops at the first candidate whose exact loss is <= the target ("reached the same exact loss"),
  at ``max_evals`` evaluations, or if CMA-ES stops by itself. A candidate that is not valid
  parameters (``from_array`` raises) or whose exact run fails costs :data:`INVALID_LOSS` and counts
  as an evaluation. CMA-ES is not held to the tune's acceptance guards (collisions are in the loss;
  curvature and jerk guards are not), and neither is the tune in the benchmark
  (``TuneConfig.guards`` false, a policy for presets that generalise): both methods take any lower
  exact loss.

``speedup`` = cmaes ``wall_s`` / proxy ``wall_s``; when CMA-ES did not reach the target within
``max_evals`` it is a lower bound (``speedup_is_lower_bound``). Before either clock starts, one
untimed, uncounted exact evaluation of the start parameters warms the exact planner (numba
caches, scenario rasters), so neither method pays that. Every evaluation is deterministic: the same
creature, seed and settings give the same evaluations and losses (wall times aside).
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np

SIGMA0 = 0.3
"""CMA-ES initial step size in log-parameter space."""
DEFAULT_MAX_EVALS = 150
INVALID_LOSS = 1.0e6
"""Exact loss given to a CMA-ES candidate that is not valid parameters or whose exact run fails
(exact losses of sensible parameters are of order 0.1-10; finite so that CMA-ES ranks it last)."""
BOUND_MARGIN = 1e-9
"""Relative margin inside the open upper limits of ``duty_at_rest`` (< 1) and ``stride_exponent`` (< 0.5)."""
_UPPER_LIMITS = {"duty_at_rest": 1.0, "stride_exponent": 0.5}
_RESERVED = ("creature", "rounds", "seed")


# --------------------------------------------------------------------------- arguments


def _check_int(name: str, value, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise ValueError(f"{name}: expected an integer >= {low}, got {value!r}")
    return int(value)


BENCH_SETUP = {"exact_scenarios": ("flat", "hills@seed=1"), "exact_seeds": (0,), "guards": False,
               "start_timing": (("stride_coefficient", 3.0),)}
"""The exact setup both methods minimise: a quarter of ``footfall tune``'s (2 scenarios x 1 seed
instead of 4 x 3), so that CMA-ES's budget of exact evaluations runs in minutes in one process,
and the tune's acceptance guards off (any lower exact loss is accepted, as by CMA-ES: the jerk
guard, relative to the start, refused the best steps from the mis-tuned start). Both start from a
mis-tuned timing, strides 30 % too long (stride_coefficient 3.0 instead of 2.3): the default weights
and timing already realise the target strides within the runs' noise, so from them neither method
has anything to find. The comparison is of the optimisers on one objective; ``config_overrides``
replaces any of it."""


def make_config(creature: str, seed: int = 0, rounds: int = 2, config_overrides: dict | None = None):
    """The :class:`tuning._tune.TuneConfig` of the benchmark: :data:`BENCH_SETUP`, then
    ``config_overrides`` (other fields)."""
    from footfall.tuning._tune import TuneConfig, check_creature

    seed = _check_int("seed", seed, 0)
    rounds = _check_int("rounds", rounds, 1)
    overrides = {**BENCH_SETUP, **dict(config_overrides or {})}
    reserved = sorted(set(overrides) & set(_RESERVED))
    if reserved:
        raise ValueError(f"config_overrides: {', '.join(reserved)} are arguments of run(), not overrides")
    fields = set(TuneConfig.__dataclass_fields__)
    unknown = sorted(set(overrides) - fields)
    if unknown:
        raise ValueError(f"config_overrides: unknown TuneConfig field(s) {', '.join(unknown)}")
    check_creature(creature)
    # from_json: lists (from JSON or a caller) become the tuples TuneConfig holds, nested ones too.
    return TuneConfig.from_json({"creature": creature, "rounds": rounds, "seed": seed, **overrides})


# --------------------------------------------------------------------------- proxy method


def _proxy_record(state: dict, wall_s: float, phases: dict, timed_until: str) -> dict:
    """Counts from a tune checkpoint: 1 evaluation of the start (``start_exact_loss``: the tune's
    reference parameters, the defaults with ``start_timing`` applied) + every line-search entry."""
    line_search = [len(r["line_search"]) for r in state["history"]]
    history = [float(state["start_exact"]["exact_loss"])]
    history += [float(e["exact_loss"]) for r in state["history"] for e in r["line_search"]]
    return {"wall_s": float(wall_s), "exact_evals": 1 + sum(line_search),
            "exact_loss": float(state["best"]["exact"]["exact_loss"]),
            "start_exact_loss": history[0], "rounds_run": len(line_search),
            "accepted_rounds": sum(bool(r["accepted"]) for r in state["history"]),
            "line_search_evals": line_search, "history": history, "phases_s": phases,
            "timed_until": timed_until}


def _phases(marks: list[tuple[str, float]], end: float) -> dict:
    """Seconds per kind of tune step, from the timestamps of its progress messages."""
    out = {"start_exact": 0.0, "harvest_fit": 0.0, "line_search": 0.0}
    for (message, start), (_, stop) in zip(marks, marks[1:] + [("", end)]):
        if message.startswith("exact loss of the start"):
            out["start_exact"] += stop - start
        elif message.endswith("harvest + fit"):
            out["harvest_fit"] += stop - start
        elif message.endswith("exact loss"):
            out["line_search"] += stop - start
    return {k: float(v) for k, v in out.items()}


def run_proxy(config, workdir: str | Path, progress=None) -> dict:
    """Run the tune's outer loop into ``workdir`` (its checkpoint stays there), without the held-out
    evaluation (``tune(..., evaluate=False)``). Counts: :func:`_proxy_record` on the checkpoint.
    """
    import json

    from footfall.tuning._tune import checkpoint_path, tune

    out = Path(workdir) / f"bench-{config.creature}.json"
    marks: list[tuple[str, float]] = []

    def hook(message, done=None, total=None):
        now = time.perf_counter()
        marks.append((message, now))
        if progress:
            progress(f"optimistix: {message}")

    t0 = time.perf_counter()
    tune(config, out, progress=hook, evaluate=False, workers=1)  # in-process, as CMA-ES's evaluations
    timed_until = "end of the outer loop"
    end = time.perf_counter()
    state = json.loads(checkpoint_path(out).read_text())
    return _proxy_record(state, end - t0, _phases(marks, end), timed_until)


# --------------------------------------------------------------------------- CMA-ES


def search_space(weights, start=None):
    """(x0, lower, upper): x = log weights (19) + log FITTED_TIMING fields (4), x0 = log of ``weights``
    (the creature's defaults, ``tuning.creature_defaults``) and of ``start`` (a ``GaitTiming``; None:
    the defaults). Upper bounds keep ``duty_at_rest`` < 1 and ``stride_exponent`` < 0.5 (their open
    ranges)."""
    from footfall.planner._timing import GaitTiming
    from footfall.tuning._fit import FITTED_TIMING

    timing = start or GaitTiming()
    x0 = np.log(np.concatenate([weights.to_array(), [getattr(timing, n) for n in FITTED_TIMING]]))
    upper = np.full(x0.shape, np.inf)
    for i, name in enumerate(FITTED_TIMING):
        if name in _UPPER_LIMITS:
            upper[x0.size - len(FITTED_TIMING) + i] = math.log(_UPPER_LIMITS[name]) + math.log1p(-BOUND_MARGIN)
    return x0, np.full(x0.shape, -np.inf), upper


def decode(x, start=None):
    """(ScoringWeights, GaitTiming) of a point x of :func:`search_space` (the timing fields not searched
    are those of ``start``, None: the defaults); raises ValueError if invalid."""
    from footfall.planner._timing import TIMING_FIELDS, GaitTiming
    from footfall.planner._weights import ScoringWeights
    from footfall.tuning._fit import FITTED_TIMING

    x = np.asarray(x, dtype=np.float64)
    n_w = len(ScoringWeights().to_array())
    if x.shape != (n_w + len(FITTED_TIMING),):
        raise ValueError(f"x: expected shape ({n_w + len(FITTED_TIMING)},), got {x.shape}")
    with np.errstate(over="ignore"):
        values = np.exp(x)
    timing = (start or GaitTiming()).to_array()
    timing[[TIMING_FIELDS.index(n) for n in FITTED_TIMING]] = values[n_w:]
    return ScoringWeights.from_array(values[:n_w]), GaitTiming.from_array(timing)


def exact_loss_of(setup, targets, x, start=None) -> tuple[float, str | None]:
    """The exact loss at x, or (:data:`INVALID_LOSS`, why) if x is not valid parameters or the
    exact run fails (one exact-planner evaluation either way)."""
    from footfall.tuning._exact import exact_metrics

    try:
        weights, timing = decode(x, start)
    except ValueError as e:
        return INVALID_LOSS, f"invalid parameters: {e}"
    try:
        loss = float(exact_metrics(setup, weights, timing, targets=targets).exact_loss)
    except (RuntimeError, ValueError, FloatingPointError) as e:
        return INVALID_LOSS, f"exact run failed: {e}"
    if not math.isfinite(loss):
        return INVALID_LOSS, "non-finite exact loss"
    return loss, None


def _cmaes_until(evaluate, x0, sigma0: float, seed: int, target: float, max_evals: int, bounds=None, say=None):
    """Seeded CMA-ES (ask/tell) on ``evaluate(x) -> loss`` until a loss <= ``target``, ``max_evals``
    evaluations, or CMA-ES's own stop. The normal samples come from ``numpy.random.default_rng(seed)``
    (CMA's ``randn`` option; its ``seed`` option would reseed numpy's global generator, and reads 0 as
    "seed from the clock"). Returns (losses in evaluation order, what stopped it, population size,
    wall seconds)."""
    import cma

    rng = np.random.default_rng(seed)
    options = {"seed": np.nan, "randn": lambda *shape: rng.standard_normal(shape), "verbose": -9,
               "verb_log": 0, "verb_disp": 0}
    if bounds is not None:
        options["bounds"] = [list(bounds[0]), list(bounds[1])]
    es = cma.CMAEvolutionStrategy(x0, sigma0, options)
    history: list[float] = []
    stopped_by = "max_evals"
    t0 = time.perf_counter()
    while len(history) < max_evals:
        if es.stop():
            stopped_by = "cma: " + ", ".join(sorted(es.stop()))
            break
        candidates = es.ask()
        losses = []
        for x in candidates:
            loss = evaluate(x)
            history.append(loss)
            losses.append(loss)
            if say:
                say(f"CMA-ES {len(history)}/{max_evals}: best {min(history):.4g} (target {target:.4g})")
            if loss <= target or len(history) >= max_evals:
                break
        if history[-1] <= target:
            stopped_by = "target"
            break
        if len(losses) == len(candidates):
            es.tell(candidates, losses)
    return history, stopped_by, es.popsize, time.perf_counter() - t0


def run_cmaes(setup, targets, target_loss: float, max_evals: int, seed: int, sigma0: float = SIGMA0,
              progress=None, start=None) -> dict:
    """Seeded CMA-ES (ask/tell) on the exact loss until a candidate's loss <= ``target_loss``,
    ``max_evals`` evaluations, or CMA-ES's own stop. ``exact_evals`` = candidates evaluated
    (a stop mid-population leaves the rest of that population unevaluated and uncounted), seeded
    as :func:`_cmaes_until` says."""
    max_evals = _check_int("max_evals", max_evals, 1)
    from footfall.tuning._defaults import creature_defaults

    x0, lower, upper = search_space(creature_defaults(setup.creature), start)
    invalid = 0

    def evaluate(x):
        nonlocal invalid
        loss, why = exact_loss_of(setup, targets, x, start)
        invalid += why is not None
        return loss

    history, stopped_by, popsize, wall = _cmaes_until(evaluate, x0, sigma0, seed, target_loss, max_evals,
                                                      bounds=(lower, upper), say=progress)
    best = min(history)
    return {"wall_s": float(wall), "exact_evals": len(history), "exact_loss": float(best),
            "reached": bool(best <= target_loss), "stopped_by": stopped_by, "invalid_evals": int(invalid),
            "popsize": int(popsize), "sigma0": float(sigma0), "dimension": int(x0.size),
            "history": [float(v) for v in history]}


# --------------------------------------------------------------------------- the benchmark


def _warm_up(setup, targets, start) -> None:
    """One untimed, uncounted exact evaluation (numba caches, rasters) before either clock starts."""
    from footfall.tuning._exact import exact_metrics

    exact_metrics(setup, timing=start, targets=targets)


def run(creature: str = "spider", seed: int = 0, max_evals: int = DEFAULT_MAX_EVALS, rounds: int = 2,
        progress=None, config_overrides: dict | None = None, workdir: str | Path | None = None) -> dict:
    """Run the benchmark; returns the ``--json`` object (module docstring for what is counted).

    ``progress(message)`` is called as work advances; ``config_overrides``: other ``TuneConfig``
    fields (e.g. a smaller exact setup for tests); ``workdir``: where the tune writes (default a
    temporary directory, removed afterwards).
    """
    from footfall.tuning._config import enable_x64
    from footfall.tuning._targets import load_targets

    max_evals = _check_int("max_evals", max_evals, 1)
    config = make_config(creature, seed=seed, rounds=rounds, config_overrides=config_overrides)
    enable_x64()
    setup = config.exact_setup()
    targets = load_targets(creatures=(config.creature,))
    say = progress or (lambda message: None)
    say("warming up the exact planner")
    _warm_up(setup, targets, config.start())
    if workdir is None:
        with tempfile.TemporaryDirectory(prefix="footfall-bench-tuning-") as folder:
            proxy = run_proxy(config, folder, progress=say)
    else:
        proxy = run_proxy(config, workdir, progress=say)
    target = proxy["exact_loss"]
    cmaes = run_cmaes(setup, targets, target, max_evals, config.seed, progress=say, start=config.start())
    return {
        "creature": config.creature, "seed": config.seed, "rounds": config.rounds, "max_evals": max_evals,
        "target_loss": target,
        "proxy": proxy, "cmaes": cmaes,
        "speedup": float(cmaes["wall_s"] / max(proxy["wall_s"], 1e-9)),
        "evals_ratio": float(cmaes["exact_evals"] / proxy["exact_evals"]),
        "reached": cmaes["reached"], "speedup_is_lower_bound": not cmaes["reached"],
        "exact_setup": setup.to_json(),
        "notes": ("speedup = cmaes wall_s / proxy wall_s; evals_ratio = cmaes exact_evals / proxy exact_evals. "
                  "proxy exact_evals = 1 (start parameters) + line-search evaluations; held-out evaluation "
                  "and Spearman harvest neither run nor counted. cmaes stops at the first candidate with "
                  "exact loss <= target_loss (the proxy's final exact loss)"
                  + ("." if cmaes["reached"] else f"; not reached in {max_evals} evaluations: speedup and "
                     "evals_ratio are lower bounds.")),
    }


def table(result: dict):
    """A rich table of :func:`run`'s result: one row per method, the speedup in the caption."""
    from rich.table import Table

    proxy, cmaes = result["proxy"], result["cmaes"]
    bound = ">= " if result.get("speedup_is_lower_bound") else ""
    caption = (f"speedup (CMA-ES wall / proxy wall): {bound}{result['speedup']:.1f}x; "
               f"exact evaluations: {bound}{result['evals_ratio']:.1f}x")
    if not cmaes["reached"]:
        caption += f"\nCMA-ES did not reach the proxy's exact loss in {result['max_evals']} evaluations"
    table = Table(title=f"Tuning {result['creature']}: same exact loss, optimistix on proxies vs CMA-ES",
                  caption=caption)
    for col in ("method", "wall s", "exact evals", "exact loss", "reached"):
        table.add_column(col, justify="left" if col == "method" else "right")
    table.add_row("optimistix (proxies)", f"{proxy['wall_s']:.1f}", str(proxy["exact_evals"]),
                  f"{proxy['exact_loss']:.4g}", "target")
    table.add_row("CMA-ES (exact)", f"{cmaes['wall_s']:.1f}", str(cmaes["exact_evals"]),
                  f"{cmaes['exact_loss']:.4g}", "yes" if cmaes["reached"] else "no")
    return table


# --------------------------------------------------------------------------- terrain / style tunes (issue 18)


def run_events(creature: str, scenarios, seed: int = 0, max_evals: int = DEFAULT_MAX_EVALS, rounds: int = 3,
               progress=None, config_overrides: dict | None = None) -> dict:
    """The same comparison for the weights of a terrain tune (``footfall bench tuning --scenarios``):

    * **proxy** -- :func:`tuning._tune_events.tune_events` without its held-out runs, in this process;
      exact evaluations = 1 (the defaults) + every line-search entry; its result is the best accepted
      loss (the mean paired run loss of :mod:`tuning._events` over the tune's runs);
    * **cmaes** -- seeded CMA-ES on x = log of the 19 ``ScoringWeights`` from the defaults (the timing
      is the targets' stride law, as in the tune), sigma0 :data:`SIGMA0`, on the same runs' mean loss,
      until a candidate reaches the proxy's loss or ``max_evals``.

    The tune's acceptance guards stay on (collisions, noise): the comparison is to the loss of the
    preset the tune writes. One untimed evaluation of the defaults warms the planner first."""
    from footfall.planner._weights import ScoringWeights
    from footfall.tuning._config import enable_x64
    from footfall.tuning._defaults import creature_defaults
    from footfall.tuning._events import event_metrics
    from footfall.tuning._targets import load_tune_targets
    from footfall.tuning._tune_events import EventTuneConfig, checkpoint_path, tune_events

    import json

    max_evals = _check_int("max_evals", max_evals, 1)
    config = EventTuneConfig(creature, scenarios=tuple(scenarios), rounds=rounds, seed=seed,
                             **dict(config_overrides or {}))
    enable_x64()
    targets = load_tune_targets(config.targets_file, creature)
    setup = config.setup()
    timing = targets.timing()
    say = progress or (lambda message: None)
    say("warming up the exact planner")
    defaults = creature_defaults(creature)
    event_metrics(setup, defaults, timing, targets)
    with tempfile.TemporaryDirectory(prefix="footfall-bench-tuning-") as folder:
        out = Path(folder) / f"bench-{creature}.json"
        t0 = time.perf_counter()
        tune_events(config, out, workers=1, evaluate=False,
                    progress=lambda message, *_: say(f"optimistix: {message}"))
        proxy_wall = time.perf_counter() - t0
        state = json.loads(checkpoint_path(out).read_text())
    line_search = [len(r["line_search"]) for r in state["history"]]
    target = float(state["best"]["exact"]["exact_loss"])
    proxy = {"wall_s": float(proxy_wall), "exact_evals": 1 + sum(line_search), "exact_loss": target,
             "start_exact_loss": float(state["default_exact"]["exact_loss"]), "rounds_run": len(line_search),
             "accepted_rounds": sum(bool(r["accepted"]) for r in state["history"])}
    x0 = np.log(defaults.to_array())

    def evaluate(x):
        try:
            return float(event_metrics(setup, ScoringWeights.from_array(np.exp(x)), timing, targets)["exact_loss"])
        except ValueError:
            return INVALID_LOSS

    history, stopped_by, popsize, wall = _cmaes_until(evaluate, x0, SIGMA0, config.seed, target, max_evals, say=say)
    best = min(history)
    cmaes = {"wall_s": float(wall), "exact_evals": len(history), "exact_loss": float(best),
             "reached": bool(best <= target), "stopped_by": stopped_by, "popsize": int(popsize),
             "sigma0": SIGMA0, "dimension": int(x0.size), "history": [float(v) for v in history]}
    return {"creature": creature, "scenarios": list(config.scenarios), "seed": config.seed, "rounds": rounds,
            "max_evals": max_evals, "target_loss": target, "proxy": proxy, "cmaes": cmaes,
            "speedup": float(wall / max(proxy_wall, 1e-9)),
            "evals_ratio": float(len(history) / proxy["exact_evals"]),
            "reached": cmaes["reached"], "speedup_is_lower_bound": not cmaes["reached"],
            "exact_setup": setup.to_json(),
            "notes": "terrain tune of the weights (tuning._tune_events); losses: mean paired run loss over the "
                     "tune's runs" + ("." if cmaes["reached"] else
                                      f"; CMA-ES did not reach it in {max_evals} evaluations: lower bounds.")}
