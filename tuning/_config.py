"""JAX settings of tuning/ (never set at ``planner`` import: the runtime does not load JAX)."""

from __future__ import annotations

import jax


def enable_x64() -> None:
    """Turn on float64 in JAX: tuning reproduces the runtime's float64 numbers. Called by
    tuning's entry points; idempotent."""
    if not jax.config.jax_enable_x64:
        jax.config.update("jax_enable_x64", True)
