"""Benchmarks and studies, run as modules from the repository root:
``python -m benchmarks.speed.X`` (timings, commit comparisons) and
``python -m benchmarks.studies.X`` (the results pages' tables). Each takes ``--quick``.
"""
