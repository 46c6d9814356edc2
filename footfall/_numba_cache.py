"""Where numba caches the compiled kernels: configured by the entry points, not on import.

numba invalidates a cached function only when *its own* source file changes, not when an njit
function it calls from another module does (nor when a module-level constant it compiled in
changes); a stale cache would run old code. So the cache lives in a folder named after a hash of
every kernel source file of ``footfall.planner`` and of the modules whose constants the kernels use:
any change there means a fresh folder. The root is ``$NUMBA_CACHE_DIR`` if set, else
``~/.cache/footfall/numba``.

The command line, the benchmarks' mains and the tests call :func:`configure_numba_cache` before
anything compiles; importing ``footfall.planner`` changes no environment variable. A program that
imports the planner itself calls it first (or lives with numba's default: a cache beside each source
file, invalidated by that file's own changes only). Processes started afterwards (Dask workers, the
renderer) inherit the folder through the environment. Importing the planner with ``NUMBA_CACHE_DIR``
set to any other folder warns (:func:`warn_if_foreign_cache`): a kernel cached there from other
sources would run their code.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import warnings
from pathlib import Path

# The planner's modules whose source a kernel compiles in: the kernels, and the modules of the
# constants (index constants, parameters) they read.
_CONSTANT_MODULES = ("_grid.py", "_params.py", "_weights.py", "_timing.py", "layout.py")


def kernel_sources_digest(folder: Path) -> str:
    """16 hex digits of a hash of the kernel sources in ``folder`` (a planner package folder): their
    names and bytes, in name order.

    Parameters
    ----------
    folder : pathlib.Path
        A folder holding ``_kernels_*.py`` and the modules of their constants.

    Returns
    -------
    str

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "_kernels_a.py").write_text("x = 1")
    ...     before = kernel_sources_digest(Path(d))
    ...     _ = (Path(d) / "layout.py").write_text("N = 2")
    ...     before != kernel_sources_digest(Path(d)), len(before)
    (True, 16)
    """
    digest = hashlib.sha256()
    sources = [*folder.glob("_kernels_*.py"), *(folder / name for name in _CONSTANT_MODULES)]
    for path in sorted(p for p in sources if p.is_file()):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def _planner_folder() -> Path:
    spec = importlib.util.find_spec("footfall.planner")  # its folder, without running its __init__
    return Path(spec.submodule_search_locations[0])


def warn_if_foreign_cache() -> bool:
    """Warn (``RuntimeWarning``) when numba caches in a folder set by hand that is not named after these
    kernel sources; return whether it warned. ``footfall.planner`` calls it on import.

    numba reuses a kernel cached in that folder as long as the kernel's own file is unchanged, with the
    code of whatever kernels it called *then*: after an edit or an upgrade of another kernel file, a
    run silently computes with the old code (a script importing the planner before
    :func:`configure_numba_cache` counted 38 leg crossings where the command line counted 2). No folder
    set by hand: numba's default, beside the sources, and no warning.

    Returns
    -------
    bool
        True if it warned.
    """
    if "numba" in sys.modules:
        import numba.core.config

        folder = numba.core.config.CACHE_DIR or os.environ.get("NUMBA_CACHE_DIR", "")
    else:
        folder = os.environ.get("NUMBA_CACHE_DIR", "")
    if not folder or Path(folder).name == kernel_sources_digest(_planner_folder()):
        return False
    warnings.warn(f"footfall.planner: NUMBA_CACHE_DIR={folder} is not named after these kernel sources, and "
                  "kernels cached there from other sources would run their old code: call "
                  "footfall.configure_numba_cache() before importing footfall.planner", RuntimeWarning, stacklevel=3)
    return True


def configure_numba_cache() -> Path:
    """Point numba's cache at ``ROOT/<digest of the kernel sources>`` and return that folder.

    Sets ``NUMBA_CACHE_DIR`` (and ``FOOTFALL_NUMBA_CACHE_ROOT``, so that a child process that calls
    it again finds the same folder rather than one nested inside it); if numba is already imported,
    its configuration too. Calling it again changes nothing. It imports neither numba nor the planner.

    Call it before importing ``footfall.planner``: numba picks a kernel's cache folder when the kernel
    is defined, so kernels imported before keep the folder of that time (a ``RuntimeWarning`` says so
    when this call moves the folder after the planner was imported).

    Returns
    -------
    pathlib.Path
        The cache folder, ``ROOT/<16 hex digits>``.

    Examples
    --------
    >>> import os
    >>> from footfall import configure_numba_cache
    >>> folder = configure_numba_cache()
    >>> os.environ["NUMBA_CACHE_DIR"] == str(folder), len(folder.name)
    (True, 16)
    >>> configure_numba_cache() == folder  # again: the same folder, not one nested inside it
    True
    """
    folder = _planner_folder()
    root = Path(os.environ.get("FOOTFALL_NUMBA_CACHE_ROOT") or os.environ.get("NUMBA_CACHE_DIR")
                or Path.home() / ".cache" / "footfall" / "numba")
    os.environ.setdefault("FOOTFALL_NUMBA_CACHE_ROOT", str(root))
    cache = root / kernel_sources_digest(folder)
    moved = os.environ.get("NUMBA_CACHE_DIR") != str(cache)
    os.environ["NUMBA_CACHE_DIR"] = str(cache)
    if moved and "footfall.planner" in sys.modules:
        warnings.warn("configure_numba_cache: footfall.planner was imported before; its kernels keep the cache "
                      "folder of that time (call this first)", RuntimeWarning, stacklevel=2)
    if "numba" in sys.modules:  # imported before: its configuration was read from the old environment
        import numba.core.config

        numba.core.config.CACHE_DIR = str(cache)
    return cache
