"""Speed benchmarks: timings and commit-vs-commit comparisons (python -m benchmarks.speed.X)."""
