"""Datasets: the plan generator, the renderer and its looks, readers of real datasets."""
