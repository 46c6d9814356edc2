"""Tuning of the scoring weights with JAX and optimistix (not built yet: issue 4)."""
