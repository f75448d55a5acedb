"""Benchmarks and evaluation CLIs.

``python -m f2n_drake.evaluate {segmentation,parse-speed,planning,navigation}``.
"""
