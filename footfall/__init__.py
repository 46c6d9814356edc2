"""footfall: procedural locomotion of multi-legged characters (Abdul Karim et al., CAVW 2012).

One namespace, by floor (each imports only the ones before it; nothing imports the command line):

* ``footfall`` (this package, the ground floor): :class:`InputError`, atomic writes
  (``footfall._atomic``), running tasks in-process or on Dask workers (``footfall._distribute``),
  where numba caches the kernels (:func:`configure_numba_cache`), the version. It imports nothing
  else of the project.
* ``footfall.planner``: the exact discrete runtime (numpy + numba; never JAX, pyvista or pxr).
* ``footfall.scenarios``: terrains, obstacles, creatures, gaits, crowds.
* ``footfall.tuning``: the JAX scoring, the proxies, the fits and the presets.
* ``footfall.benchmarks``, ``footfall.reports``: measurements, evaluation, pictures, USD.
* ``footfall.cli``: the ``footfall`` command.
"""

from importlib.metadata import PackageNotFoundError, version

from footfall._errors import InputError
from footfall._numba_cache import configure_numba_cache

try:
    __version__ = version("footfall")  # one place: pyproject.toml's [project] version
except PackageNotFoundError:  # run from a source tree that was never installed
    __version__ = "unknown"

__all__ = ["InputError", "__version__", "configure_numba_cache"]
