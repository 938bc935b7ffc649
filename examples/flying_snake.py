"""A real flying-snake glide end to end: ingest, chain description, preprocess, learners.

Usage::

    .venv/bin/python examples/flying_snake.py [REFDATA]

REFDATA is the folder holding ``flying_snake_qualisys/413_91.tsv`` (default
``../shared/refdata``). Prints the shape modes' explained variance, the phase rate, the
number of waves along the body, and the hold-out errors of the learners.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from suds_exp.body.real_snake import run_real_snake  # noqa: E402

HERE = Path(__file__).resolve().parent


def main() -> None:
    refdata = Path(sys.argv[1] if len(sys.argv) > 1 else HERE.parents[1] / "shared" / "refdata")
    capture = refdata / "flying_snake_qualisys" / "413_91.tsv"
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        out = run_real_snake([capture], HERE / "flying_snake.toml", Path(tmp) / "snake.duckdb")
    ev = ", ".join(f"{100 * r:.1f}%" for r in out["explained_variance_ratio"])
    print(f"shape modes explain {ev}")
    print("phase rate " + ", ".join(f"{r:.2f} Hz" for r in out["phase_rate_hz"]))
    print(f"waves along the body (modes 1-2): {out['waves_along_body']:.2f}")
    print(out["errors"].round(1).to_string(index=False))
    print(f"{time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main()
