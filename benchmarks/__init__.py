"""Benchmarks behind `footfall bench`."""
