"""The ``footfall`` command line (the top floor: it imports every package; none imports it).

Every command turns bad input into one line on stderr, ``footfall: error: FILE:
FIELD: REASON``, and exit code 2; ``--json`` output is one JSON object on stdout.
"""

from footfall.cli._commands import app, main

__all__ = ["app", "main"]
