"""Shipped model files: segmenter weights with their model card, and the robot description.

Files here are found with :func:`model_path`; set ``F2N_DRAKE_MODELS`` to use another folder.
"""

import os
from pathlib import Path


def model_path(name: str) -> Path:
    """Path of a shipped model file, or of ``$F2N_DRAKE_MODELS/name`` when that is set."""
    root = os.environ.get("F2N_DRAKE_MODELS")
    return Path(root) / name if root else Path(__file__).parent / name
