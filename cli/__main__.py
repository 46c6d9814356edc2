"""``python -m footfall.cli ARGS``: the console script ``footfall ARGS``."""

from footfall.cli._commands import main

if __name__ == "__main__":  # not on import (a module walker imports every module)
    main()
