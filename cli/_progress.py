"""Progress of a long command on stderr, for a person at a terminal or a log file.

On a terminal a live line (spinner, description, elapsed time) is redrawn in place and
erased at the end. Off a terminal (stderr redirected to a file or a pipe, a CI log) a
redrawn line would be invisible or garbage, so plain lines are printed instead::

    footfall run: [2/4] tune: round 1: harvest (41 s)

one when the step changes and then one every few seconds (``interval``) while the
work lasts, even when the work reports nothing, so that a log shows it is alive.
Nothing is printed before the first :meth:`Progress.update`: a command that refuses
its input prints its one error line alone.
"""

from __future__ import annotations

import sys
import threading
import time
from typing import IO


class Progress:
    """A progress display that starts with the first update (see the module docstring).

    Parameters
    ----------
    label:
        What runs, e.g. ``"footfall run"``; it starts every plain line.
    enabled:
        False: print nothing (``--json`` output, quiet runs).
    interval:
        Seconds between two plain lines of the same step (off a terminal).
    stream:
        Where to print (default ``sys.stderr``); a terminal gets the live line.
    """

    def __init__(self, label: str, *, enabled: bool = True, interval: float = 5.0, stream: IO[str] | None = None):
        self.label = label
        self.enabled = enabled
        self.interval = interval
        self.stream = stream if stream is not None else sys.stderr
        self.live = enabled and bool(getattr(self.stream, "isatty", lambda: False)())
        self._t0 = time.perf_counter()
        self._lock = threading.Lock()
        self._description: str | None = None
        self._step: str | None = None
        self._last_line = 0.0
        self._rich = None
        self._task = None
        self._stop = threading.Event()
        self._ticker: threading.Thread | None = None

    def __enter__(self) -> "Progress":
        self._t0 = time.perf_counter()
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def elapsed(self) -> float:
        """Seconds since the display was entered."""
        return time.perf_counter() - self._t0

    def update(self, description: str, step: str | None = None) -> None:
        """Show ``description``; ``step`` names the stage it belongs to (a new step prints a line at once)."""
        if not self.enabled:
            return
        with self._lock:
            new_step = step is not None and step != self._step
            self._description, self._step = description, step if step is not None else self._step
            if self.live:
                self._live_update(description)
                return
            now = time.perf_counter()
            if new_step or self._ticker is None or now - self._last_line >= self.interval:
                self._print_line(now)
            if self._ticker is None:
                # The work may report nothing for minutes (a compile, a long exact run): a line
                # every `interval` seconds shows that it is alive.
                self._ticker = threading.Thread(target=self._tick, name="footfall-progress", daemon=True)
                self._ticker.start()

    def close(self) -> None:
        """Stop the display (erase the live line; stop the plain lines)."""
        self._stop.set()
        if self._ticker is not None:
            self._ticker.join(timeout=1.0)
        if self._rich is not None:
            self._rich.stop()
            self._rich = None

    def _print_line(self, now: float) -> None:
        self._last_line = now
        print(f"{self.label}: {self._description} ({now - self._t0:.0f} s)", file=self.stream, flush=True)

    def _tick(self) -> None:
        while not self._stop.wait(min(1.0, self.interval)):
            with self._lock:
                now = time.perf_counter()
                if now - self._last_line >= self.interval and not self._stop.is_set():
                    self._print_line(now)

    def _live_update(self, description: str) -> None:
        if self._rich is None:
            from rich.console import Console
            from rich.progress import Progress as RichProgress
            from rich.progress import SpinnerColumn, TextColumn, TimeElapsedColumn

            self._rich = RichProgress(SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn(),
                                      console=Console(file=self.stream, highlight=False), transient=True)
            self._rich.start()
            self._task = self._rich.add_task(description, total=None)
        self._rich.update(self._task, description=description)
