"""Evaluation reports, pictures and USD export (not built yet: issue 5)."""
