"""footfall: procedural locomotion of multi-legged characters (Abdul Karim et al., CAVW 2012)."""

from importlib.metadata import PackageNotFoundError, version

from footfall._errors import InputError

try:
    __version__ = version("footfall")  # one place: pyproject.toml's [project] version
except PackageNotFoundError:  # run from a source tree that was never installed
    __version__ = "unknown"

__all__ = ["InputError", "__version__"]
