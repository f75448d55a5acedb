"""Outputs of a run: exports for other tools, figures, and the writer of ``--out``."""
