"""``python -m f2n_drake.train``: the segmenter's training CLI (``f2n_drake.segmenter.train``)."""

import sys

from f2n_drake.core.errors import run_cli
from f2n_drake.segmenter.train import main

if __name__ == "__main__":
    sys.exit(run_cli(main))
