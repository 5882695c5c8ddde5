"""``python -m network.throats``: :mod:`network.throatlist` under the command name of the
throat-export contract (``python -m network.throats PACKING --out THROATS.csv``, the input of
``python -m cache.precompute``); the code, options and exit codes are that module's.
"""

import sys

from .throatlist import HEADER, build_parser
from .throatlist import main as _main

__all__ = ["HEADER", "build_parser", "main"]

PROG = "python -m network.throats"


def main(argv=None) -> int:
    """Run the command as ``python -m network.throats``; exit status 0, 1 or 2."""
    return _main(argv, prog=PROG)


if __name__ == "__main__":
    sys.exit(main())
