"""Shipped model files: segmenter weights (``segmenter.pt``, and ``storage.pt``, the network that
reads closets beside it) with their model card, and one YAML per robot (``turtlebot3_burger.yaml``,
``uav.yaml``, read by ``f2n_drake.mapping.robots``).

Files here are found with :func:`model_path`. Setting ``F2N_DRAKE_MODELS`` to a folder makes that
folder searched first (e.g. for your own segmenter weights); files it lacks still come from here,
except the storage network, used only beside the segmenter weights of its own folder.
"""

import os
from pathlib import Path

SHIPPED = Path(__file__).parent


def model_path(name: str) -> Path:
    """``$F2N_DRAKE_MODELS/name`` when that is set and exists, else the shipped file."""
    root = os.environ.get("F2N_DRAKE_MODELS")
    if root and (Path(root) / name).exists():
        return Path(root) / name
    return SHIPPED / name
