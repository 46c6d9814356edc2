"""Where numba caches the compiled kernels.

numba invalidates a cached function only when *its own* source file changes, not
when an njit function it calls from another module does (nor when a module-level
constant it compiled in changes); a stale cache would run old code. So the cache
lives in a folder named after a hash of every kernel source file of this package
and of the modules whose constants the kernels use: any change there means a
fresh folder.
The root is ``$NUMBA_CACHE_DIR`` if set, else ``~/.cache/footfall/numba``.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path


def configure_numba_cache() -> Path:
    here = Path(__file__).resolve().parent
    digest = hashlib.sha256()
    # The kernels, and the modules whose constants (index constants) they compile in.
    sources = [*here.glob("_kernels_*.py"), *(here / n for n in ("_grid.py", "_params.py", "_weights.py", "_timing.py", "layout.py"))]
    for path in sorted(sources):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    root = Path(os.environ.get("FOOTFALL_NUMBA_CACHE_ROOT") or os.environ.get("NUMBA_CACHE_DIR")
                or Path.home() / ".cache" / "footfall" / "numba")
    os.environ.setdefault("FOOTFALL_NUMBA_CACHE_ROOT", str(root))
    folder = root / digest.hexdigest()[:16]
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    try:
        import numba.core.config

        numba.core.config.CACHE_DIR = str(folder)
    except ImportError:  # pragma: no cover - numba is a dependency
        pass
    return folder
