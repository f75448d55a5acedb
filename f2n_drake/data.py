"""``python -m f2n_drake.data``: the datasets CLI (``f2n_drake.datasets.cli``)."""

import sys

from f2n_drake.core.errors import run_cli
from f2n_drake.datasets.cli import main

if __name__ == "__main__":
    sys.exit(run_cli(main))
