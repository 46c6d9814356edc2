"""footfall: procedural locomotion of multi-legged characters (Abdul Karim et al., CAVW 2012)."""

from footfall._errors import InputError

__version__ = "0.1.0"

__all__ = ["InputError", "__version__"]
