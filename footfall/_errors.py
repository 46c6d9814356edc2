"""The one error type for bad input, shared by every package.

A user who feeds footfall a malformed scenario, preset or recording gets a
single line naming the file, the field and the reason; the CLI turns an
:class:`InputError` into that line on stderr and exit code 2.
"""

from __future__ import annotations

from pathlib import Path


class InputError(ValueError):
    """Bad input from outside the program (files, CLI arguments, creatures).

    Parameters
    ----------
    file:
        The file (or ``"builtin:NAME"``, or ``"argument"``) the input came from.
    field:
        Dotted path of the offending field, e.g. ``obstacles[2].size``.
    reason:
        Why it is refused, phrased for the user.

    Examples
    --------
    >>> from footfall import InputError
    >>> error = InputError("my_scenario.toml", "obstacles[2].size", "expected 3 positive numbers")
    >>> str(error)
    'my_scenario.toml: obstacles[2].size: expected 3 positive numbers'
    >>> isinstance(error, ValueError), error.field
    (True, 'obstacles[2].size')
    """

    def __init__(self, file: str | Path, field: str, reason: str) -> None:
        self.file = str(file)
        self.field = field
        self.reason = reason
        super().__init__(f"{self.file}: {self.field}: {self.reason}")
