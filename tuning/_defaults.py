"""A creature's default scoring weights, where tuning starts and what its presets are measured against."""

from __future__ import annotations


def creature_defaults(creature: str):
    """The runtime's default :class:`planner.ScoringWeights` for ``creature`` (a built-in name or a
    creature file): the weights ``init_crowd`` gives it on ``flat`` when none are passed
    (:func:`planner.creature_walk`: :func:`planner.default_weights` at its rest radius and the leg room
    of its walk there; no world is built).

    Parameters
    ----------
    creature : str
        A built-in creature's name or a creature file (``scenarios.load_creature``).

    Returns
    -------
    footfall.planner.ScoringWeights

    Examples
    --------
    >>> from footfall.planner import ScoringWeights
    >>> from footfall.tuning import creature_defaults
    >>> creature_defaults("spider") == ScoringWeights()          # the size the defaults are written for
    True
    >>> round(creature_defaults("ant").clearance_ref_m, 4)        # 0.47 x the spider's 7 cm: the ant's size
    0.033
    """
    from footfall.planner import GaitTiming, creature_walk
    from footfall.scenarios import load_creature, load_scenario

    flat = load_scenario("flat").crowd
    return creature_walk(load_creature(creature), GaitTiming(), flat.speed, flat.feet_spacing).weights
