"""Benchmarks and evaluation CLIs: python -m f2n_drake.evaluate {segmentation,planning,navigation}."""
