"""Synthetic residential floor plans and buildings with exact ground truth."""
