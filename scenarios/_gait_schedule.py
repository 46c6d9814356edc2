"""Each creature's gaits by speed: the built-in schedules and the generated default.

See :mod:`planner._gait_schedule` for what a schedule does at run time. The built-in
creatures change gait as the biomechanics notes say (``shared/biomechanics.md``):

* quadruped: lateral-sequence walk, trot above Fr = 0.35 (walk below about 0.3, trot above
  about 0.5: Alexander & Jayes 1983);
* ant: tetrapod, tripod above Fr = 0.1 (insects move from tetrapod-like coordination to
  tripods as speed rises; Mendes et al. 2013, Wosnitza et al. 2013);
* spider: metachronal wave, alternating tetrapods above Fr = 0.2 (Wilson 1967: the wave
  shortens to alternating tetrapods as frequency rises);
* robot5 and every other creature: one gait (its default, generated from the morphology
  when no built-in fits, :func:`scenarios.default_gait`), whose duty factor falls with speed.

A gait named by the user (``--gait``, ``[crowd] gait``) is used alone: the schedule is that
one gait.
"""

from __future__ import annotations

from footfall.planner._gait_schedule import GaitSchedule

BUILTIN_SCHEDULES: dict[str, tuple[tuple[str, ...], tuple[float, ...]]] = {
    "quadruped": (("quadruped-walk", "quadruped-trot"), (0.25,)),
    "ant": (("ant-tetrapod", "ant-tripod"), (0.1,)),
    "spider": (("spider-metachronal-wave", "spider-alternating-tetrapod"), (0.2,)),
}
"""Built-in creature name -> (gait names slowest first, Froude numbers of the changes up)."""


def gait_schedule(creature, gait=None) -> GaitSchedule:
    """The gaits ``creature`` walks with by speed.

    Parameters
    ----------
    creature : scenarios.Creature
    gait : scenarios.Gait, str, path or None
        A gait (value, built-in name or file) to use alone; ``None``: the creature's schedule
        (:data:`BUILTIN_SCHEDULES` for a built-in creature whose legs it names, else its
        default gait alone).
    """
    from footfall._errors import InputError
    from footfall.scenarios._gaits import load_gait

    if gait is not None:
        value = gait if hasattr(gait, "swing_start") else load_gait(gait, creature)
        return GaitSchedule((value,), ())
    names, ups = BUILTIN_SCHEDULES.get(creature.name, ((), ()))
    if names:
        try:
            return GaitSchedule(tuple(load_gait(n, creature) for n in names), ups)
        except InputError:  # a user creature that borrows a built-in name but not its legs
            pass
    return GaitSchedule((_default_gait(creature),), ())


def _default_gait(creature):
    import footfall.scenarios._gaits as gaits

    if hasattr(gaits, "default_gait"):
        return gaits.default_gait(creature)
    return gaits.load_gait(gaits.default_gait_name(creature.name), creature)
