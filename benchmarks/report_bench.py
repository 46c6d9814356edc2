"""The quick report's wall time (``footfall report --quick``), first run and warm.

The test suite asserts no wall time (issue 20, item 6): how long the quick report takes depends on
the machine, its load and the numba cache, so it is measured here instead. Each run is the command
the tests run, ``python -m footfall.cli report --quick --out <tmp> --json``, in a subprocess,
headless (VTK on EGL), timed from start to exit:

* ``first``: with an empty numba cache of its own (every kernel compiled: a fresh checkout, or the
  first run after a kernel changed);
* ``warm``: again with that cache filled (``repeats`` runs; the table shows each and the median).

Run it with ``python -m footfall.benchmarks.report_bench [--repeats N] [--workers N]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HEADLESS = {"VTK_DEFAULT_OPENGL_WINDOW": "vtkEGLRenderWindow"}


def time_quick_report(out: Path, cache: Path, workers: int | None = None) -> tuple[float, dict]:
    """(wall seconds, --json summary) of one quick report written to ``out`` with numba cache ``cache``."""
    env = dict(os.environ, **HEADLESS, NUMBA_CACHE_DIR=str(cache), FOOTFALL_NUMBA_CACHE_ROOT=str(cache))
    cmd = [sys.executable, "-m", "footfall.cli", "report", "--quick", "--out", str(out), "--json"]
    if workers is not None:
        cmd += ["--workers", str(workers)]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    seconds = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"footfall report --quick failed ({proc.returncode}):\n{proc.stderr[-2000:]}")
    return seconds, json.loads(proc.stdout)


def run(repeats: int = 2, workers: int | None = None, progress=None) -> list[dict]:
    """Rows of the table: the first run (empty numba cache), then ``repeats`` warm runs."""
    rows = []
    with tempfile.TemporaryDirectory(prefix="report-bench-") as tmp:
        cache = Path(tmp) / "numba"
        for i in range(1 + repeats):
            kind = "first" if i == 0 else "warm"
            if progress:
                progress(f"quick report, {kind} run {i if i else ''}".rstrip())
            seconds, summary = time_quick_report(Path(tmp) / f"report-{i}", cache, workers)
            rows.append({"run": kind if i == 0 else f"warm {i}", "numba_cache": "empty" if i == 0 else "filled",
                         "wall_s": seconds, "sweep_rows": len(summary.get("rows", []))})
    return rows


def markdown(rows: list[dict]) -> str:
    lines = ["| run | numba cache | wall s | sweep rows |", "|---|---|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['run']} | {r['numba_cache']} | {r['wall_s']:.1f} | {r['sweep_rows']} |")
    warm = [r["wall_s"] for r in rows if r["numba_cache"] == "filled"]
    if warm:
        lines.append(f"| warm median | filled | {statistics.median(warm):.1f} | |")
    return "\n".join(lines)


if __name__ == "__main__":  # python -m footfall.benchmarks.report_bench [--repeats N] [--workers N]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2, help="warm runs after the first (default 2)")
    parser.add_argument("--workers", type=int, default=None, help="footfall report --workers (default: its own)")
    args = parser.parse_args()
    print(markdown(run(repeats=args.repeats, workers=args.workers, progress=lambda m: print(m, file=sys.stderr))))
