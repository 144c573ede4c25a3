"""``python -m roughfe.cli``: the ``roughfe`` command."""
import sys

from . import main

if __name__ == "__main__":
    sys.exit(main())
