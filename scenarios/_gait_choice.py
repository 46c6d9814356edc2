"""The gait a run walks with: the ``--gait`` option, the scenario's ``[crowd] gait`` or the creature's
default; and the note when the timing model changes an authored gait's duty factor."""

from __future__ import annotations


def resolve_gait(scenario, creature, option: str | None = None):
    """The gait a run walks with and where it came from: (gait, label, authored).

    ``--gait`` (``option``) wins over the scenario's ``[crowd] gait`` (``scenario`` None: not
    looked at, e.g. when ``--creature`` replaced the scenario's creature), which wins over the
    creature's default (:func:`scenarios.default_gait`: its built-in default, or one
    generated from its morphology). ``authored`` is True for a gait the user named (not
    ``"default"``): its duty factor is the user's, and :func:`duty_factor_note` may apply.
    """
    from footfall.scenarios import DEFAULT_GAIT, load_gait
    from footfall.scenarios._gait_schedule import gait_schedule

    reference = option if option is not None else None if scenario is None else scenario.crowd.gait
    if reference is None or reference == DEFAULT_GAIT:
        # The creature's gaits by speed (walk -> trot, ...; one gait for a creature with no schedule).
        return gait_schedule(creature), DEFAULT_GAIT, False
    return load_gait(reference, creature), reference, True


def duty_factor_note(gait, label: str, creature, speed: float, timing=None) -> str | None:
    """One line when the timing model changes an authored gait's duty factor at ``speed`` (m/s), else None.

    A run rescales every gait's swing durations so that their mean follows the duty factor
    of the speed (``planner._timing.duty_factor``, ``scaled_swing_durations``); the pattern
    of starts is kept. Differences under 0.005 are not worth a line.
    """
    from footfall.planner._timing import GaitTiming, duty_factor, hip_height

    imposed = float(duty_factor(timing or GaitTiming(), float(speed), hip_height(creature)))
    authored = gait.duty_factor
    if abs(imposed - authored) < 0.005:
        return None
    return (f"gait {label}: authored duty factor {authored:.2f} becomes {imposed:.2f} at {float(speed):.2f} m/s "
            "(swing durations follow the speed; see scenarios/README.md)")


def say_duty_factor(gait, label: str, authored: bool, creature, speed: float, timing=None) -> None:
    """Print :func:`duty_factor_note` on stderr (``footfall: note: ...``) for a gait the user authored."""
    import sys

    note = duty_factor_note(gait, label, creature, speed, timing) if authored else None
    if note:
        print(f"footfall: note: {note}", file=sys.stderr)
