"""``python -m network.report``: runs :func:`network.report.cli.main`."""

from .._cli import finish
from .cli import main

if __name__ == "__main__":
    finish(main())
