"""Scientific studies whose tables the results pages quote (python -m benchmarks.studies.X)."""
