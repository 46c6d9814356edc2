"""JAX settings of tuning/ (never set at ``planner`` import: the runtime does not load JAX)."""

from __future__ import annotations

import os
from pathlib import Path

import jax


def enable_x64() -> None:
    """Turn on float64 in JAX: tuning reproduces the runtime's float64 numbers, and keep JAX's
    compiled programs on disk (:func:`use_compilation_cache`). Called by tuning's entry points;
    idempotent.

    Call it before creating any JAX array that should hold float64 numbers: arrays made before
    it stay float32. It sets JAX's global configuration, so it affects the whole process.

    Returns
    -------
    None

    See Also
    --------
    use_compilation_cache : where the compiled programs are kept.

    Examples
    --------
    >>> import jax
    >>> import jax.numpy as jnp
    >>> from footfall.tuning import enable_x64
    >>> enable_x64()
    >>> jax.config.jax_enable_x64
    True
    >>> jnp.asarray(0.1).dtype                  # float64, as the runtime computes
    dtype('float64')
    >>> enable_x64()                             # a second call changes nothing
    >>> jnp.ones(2).dtype
    dtype('float64')
    """
    if not jax.config.jax_enable_x64:
        jax.config.update("jax_enable_x64", True)
    use_compilation_cache()


def use_compilation_cache() -> Path | None:
    """JAX's persistent compilation cache in ``$FOOTFALL_JAX_CACHE_DIR``, else
    ``~/.cache/footfall/jax`` (every program, however quick to compile).

    Why: a tune compiles about 250 small programs (11 s of its 29 s in ``footfall run --quick``);
    JAX keys each cached program by the program itself and JAX's version, so a changed formula
    compiles afresh and a stale entry is never used. Returns the folder, or None when a cache
    folder is configured already (by the user, or by an earlier call: it is kept)."""
    if jax.config.jax_compilation_cache_dir:
        return None
    folder = Path(os.environ.get("FOOTFALL_JAX_CACHE_DIR") or Path.home() / ".cache" / "footfall" / "jax")
    jax.config.update("jax_compilation_cache_dir", str(folder))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    return folder
