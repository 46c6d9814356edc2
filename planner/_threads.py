"""How the numba kernels' worker threads wait between two parallel regions.

numba's OpenMP layer (libgomp) lets an idle worker spin on its core for a while after each
parallel region, by default, so the next region starts without a wake-up. On a machine whose
cores are all busy (2 cores shared with other programs, issue 15) the spinning workers take the
cores from the main thread and from each other, and a region then waits for a descheduled
worker: a frame of 1000 spiders took about 3 x as long (170-230 ms instead of 52-81 ms, the same
runs with ``OMP_WAIT_POLICY=PASSIVE``, the workqueue layer or a single thread). Passive workers
sleep at once; on an idle machine that costs a wake-up per region, and they add up: 100 spiders
with LOD off took 6.4 ms per frame passive against 5.4 ms active (quiet 2-core machine, load
0.8). So the policy is chosen from the machine's load when :mod:`planner` is imported: passive
when the 1-minute load average is at least the number of cores, the OpenMP default otherwise.
Results do not depend on it (every kernel gives the same numbers on any number of threads). Set
``OMP_WAIT_POLICY`` yourself to override.
"""

from __future__ import annotations

import contextlib
import os


def configure_worker_wait() -> None:
    """``OMP_WAIT_POLICY=PASSIVE`` on a loaded machine, unless already set (read when libgomp loads,
    at the first parallel kernel, so this runs on importing :mod:`planner`)."""
    try:
        loaded = os.getloadavg()[0] >= (os.cpu_count() or 1)
    except OSError:  # no load average on this platform
        loaded = False
    if loaded:
        os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")


@contextlib.contextmanager
def single_threaded():
    """Run the numba kernels on one thread inside the ``with`` block, and give back the thread count
    it had on the way out (an exception included).

    A few characters plan a few feet per frame: fanning each small kernel call out over the cores
    costs more than it saves (x20 on a busy 2-core machine), and one thread leaves the other cores
    to the other tasks of a sweep. Results do not depend on it.

    Yields
    ------
    None
        The block runs with ``numba.get_num_threads() == 1``.

    Examples
    --------
    >>> import numba
    >>> from footfall.planner import single_threaded
    >>> before = numba.get_num_threads()
    >>> with single_threaded():
    ...     numba.get_num_threads()
    1
    >>> numba.get_num_threads() == before
    True
    """
    import numba

    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(threads)
