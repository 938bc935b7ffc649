"""What the benchmark scripts share: the command line with its ``--quick`` smoke mode, and
for the commit comparisons a baseline's export, alternating rounds, the worker process and
the median/ratio table.

A comparison runs the same worker on two trees: an export of the baseline commit (`git
archive` of `suds_exp/`, `cli.py` and `pyproject.toml` into a temporary folder) and the
working tree. Rounds alternate (A B A B ...), so a change in the machine's load hits both
sides. A worker is a
``python -m benchmarks.<...> --worker ...`` process whose `suds_exp` is its tree's: the
tree comes first on its path, then the working tree's root for the `benchmarks` package
itself (an export holds no `benchmarks/`). It prints one JSON document as its last line.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tarfile
import tempfile
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from io import BytesIO
from pathlib import Path
from statistics import median

#: The working tree's root (the repository checkout these benchmarks belong to).
ROOT = Path(__file__).resolve().parents[1]
#: What an export of a baseline holds: the package, the command layer, and pyproject.toml,
#: by which `python -m suds_exp` knows a checkout (and loads its cli.py).
EXPORTED = ("suds_exp", "cli.py", "pyproject.toml")


def export(commit: str, folder: Path, paths: Sequence[str] = EXPORTED) -> None:
    """Write ``paths`` as they are at ``commit`` into ``folder`` (`git archive`)."""
    data = subprocess.run(
        ["git", "archive", commit, *paths], cwd=ROOT, check=True, capture_output=True
    ).stdout
    with tarfile.open(fileobj=BytesIO(data)) as tar:
        tar.extractall(folder, filter="data")


@contextmanager
def baseline_tree(baseline: str) -> Iterator[Path]:
    """The tree to measure as the baseline: ``baseline`` itself when it is a folder (a
    checkout, e.g. a `git worktree add`), else an export of that commit, removed after."""
    if Path(baseline).is_dir():
        yield Path(baseline)
        return
    with tempfile.TemporaryDirectory(prefix="suds-baseline-") as tmp:
        export(baseline, Path(tmp))
        yield Path(tmp)


def alternate(baseline: str, rounds: int, run: Callable[[Path], object]) -> tuple[list, list]:
    """``run(tree)`` on the baseline's tree (`baseline_tree`) and on the working tree, in
    turn, ``rounds`` times; returns the baseline's results and the working tree's."""
    with baseline_tree(baseline) as tree:
        base, now = [], []
        for _ in range(rounds):
            base.append(run(tree))
            now.append(run(ROOT))
    return base, now


def tree_env(tree: Path, **extra: str) -> dict[str, str]:
    """The environment of a process that imports ``tree``'s `suds_exp` (and `cli`), with
    the working tree's `benchmarks` package behind it; ``extra`` variables added."""
    path = str(tree) if tree == ROOT else os.pathsep.join([str(tree), str(ROOT)])
    return dict(os.environ, PYTHONPATH=path, **extra)


def run_in(tree: Path, *args: str, **env: str) -> str:
    """The last line printed by ``python ARGS`` run in ``tree`` (its working folder, first
    on its path); ``env``: extra environment variables."""
    res = subprocess.run(
        [sys.executable, *args],
        env=tree_env(tree, **env),
        check=True,
        capture_output=True,
        text=True,
        cwd=tree,
    )
    return res.stdout.splitlines()[-1]


def worker(tree: Path, module: str, *args: str, **env: str):
    """The JSON document a ``python -m module --worker ARGS`` process on ``tree`` prints."""
    return json.loads(run_in(tree, "-m", module, "--worker", *args, **env))


def ratios(base: Iterable[float], now: Iterable[float]) -> list[float]:
    """Round by round baseline / now, sorted (how many times faster the working tree is)."""
    return sorted(b / n for b, n in zip(base, now, strict=True))


def speedup(base: Iterable[float], now: Iterable[float], digits: int = 2) -> str:
    """``"median [min, max]"`` of the per-round ratios baseline / now, e.g. ``1.52x [1.3,
    1.7]``."""
    r = ratios(base, now)
    return f"{median(r):.{digits}f}x [{r[0]:.{digits}f}, {r[-1]:.{digits}f}]"


def same(digests: Iterable[str]) -> bool:
    """Whether every run produced the same output digest."""
    return len(set(digests)) == 1


def table(header: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    """A Markdown table (as the results pages quote it)."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def script_parser(
    description: str, quick: str = "a smoke run at tiny sizes"
) -> argparse.ArgumentParser:
    """A script's argument parser with its ``--quick`` flag (help ``quick``), the smoke mode
    every script has and tests/test_benchmarks_smoke.py runs."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--quick", action="store_true", help=quick)
    return parser


def comparison_parser(
    description: str, baseline: str, rounds: int, rounds_flag: str = "--rounds"
) -> argparse.ArgumentParser:
    """`script_parser` with a commit comparison's options: ``--baseline`` (default
    ``baseline``: the commit the working tree is measured against; `alternate` also takes
    a checkout's folder) and ``rounds_flag`` (default ``rounds``: rounds a side)."""
    parser = script_parser(description)
    parser.add_argument("--baseline", default=baseline)
    parser.add_argument(rounds_flag, type=int, default=rounds)
    return parser
