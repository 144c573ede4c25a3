"""``python -m roughfe``: the ``roughfe`` command (as ``python -m roughfe.cli``)."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
