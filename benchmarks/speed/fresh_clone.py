"""`make test` (or `make demo`) from a fresh clone, against a baseline commit, same run.

Usage (from the repository root)::

    python3 -m benchmarks.speed.fresh_clone [--baseline b16e0d5] [--rounds 3] [--target test]

What a newcomer does (the README's commands), timed: each round clones the repository
into a new folder beside it (so ``../shared`` is the same one the checkout sees), checks
out the commit, and runs ``make .venv/.installed`` (the install: venv, dependencies, the
simulator's kernels and the bytecode compiled) then ``make TARGET``, each timed with a
wall clock. Rounds alternate the baseline and the working tree's ``HEAD`` (A B A B ...),
so a change in the machine's load hits both; the load average at each start is printed.
Uncommitted changes are not measured: commit first.

Caches outside the clone stay as they are between rounds (uv's download cache in
``~/.cache/uv``): the figures are those of a machine that has installed once before,
as in the project's idle re-measurements; a cold cache adds the download time.
The clones are removed afterwards unless ``--keep``. ``--quick``: one round, the clones
and ``make --dry-run`` in place of the install and the target (a smoke run of the
machinery, no install).
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from statistics import median

from benchmarks._harness import ROOT, script_parser


def _git(*args: str, cwd: Path = ROOT) -> str:
    return subprocess.run(
        ["git", *args], cwd=cwd, check=True, capture_output=True, text=True
    ).stdout.strip()


def _timed(cmd: list[str], cwd: Path) -> tuple[float, str, int]:
    """Wall seconds, the last lines of the output and the exit code of ``cmd``."""
    started = time.perf_counter()
    # its own process group, so an interrupted run stops make's children (uv, pytest's
    # workers) too, before the clone is removed
    proc = subprocess.Popen(
        cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        start_new_session=True,
    )  # fmt: skip
    try:
        out, _ = proc.communicate()
    except BaseException:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        raise
    wall = time.perf_counter() - started
    tail = "\n".join(out.strip().splitlines()[-3:])
    return wall, tail, proc.returncode


def _outcome(tail: str) -> str:
    """pytest's summary ("585 passed, 2 skipped"), else the last line."""
    found = re.findall(r"\d+ (?:passed|failed|skipped|errors?)", tail)
    return ", ".join(found) if found else tail.splitlines()[-1] if tail else ""


def one_round(commit: str, target: str, keep: bool, dry_run: bool = False) -> dict:
    """Clone ``commit`` beside the repository and time the install and ``make target``."""
    # beside the repository: the clone's ../shared is the checkout's
    repo = Path(tempfile.mkdtemp(prefix=".fresh-clone-", dir=ROOT.parent))
    try:
        _git("clone", "-q", str(ROOT), str(repo))
        _git("checkout", "-q", commit, cwd=repo)
        load = os.getloadavg()[0]
        make = ["make", "--dry-run"] if dry_run else ["make"]
        install, tail, rc = _timed([*make, ".venv/.installed"], repo)
        if rc != 0:
            raise SystemExit(f"{commit}: the install failed:\n{tail}")
        run, tail, rc = _timed([*make, target], repo)
        return {
            "commit": commit,
            "load": load,
            "install": install,
            "run": run,
            "total": install + run,
            "rc": rc,
            "outcome": _outcome(tail),
        }
    finally:
        if not keep:
            shutil.rmtree(repo, ignore_errors=True)


def main(argv: list[str] | None = None) -> int:
    ap = script_parser(__doc__.splitlines()[0], "a smoke run: make --dry-run")
    ap.add_argument("--baseline", default="b16e0d5", help="commit to compare with")
    ap.add_argument("--rounds", type=int, default=3, help="rounds per side")
    ap.add_argument("--target", default="test", choices=("test", "demo"))
    ap.add_argument("--keep", action="store_true", help="keep the clones")
    args = ap.parse_args(argv)
    if args.quick:
        args.rounds = 1
    # a terminated run still removes its clone (the `finally` of `one_round`)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))

    sides = {"baseline": _git("rev-parse", "--short", args.baseline)}
    sides["HEAD"] = _git("rev-parse", "--short", "HEAD")
    if _git("status", "--porcelain", "--untracked-files=no"):
        print("note: uncommitted changes are not measured (HEAD is)", file=sys.stderr)
    rows = []
    print(f"make {args.target} from a fresh clone; {args.rounds} rounds per side")
    print(f"{'round':>5} {'side':>8} {'commit':>8} {'load':>5} {'install':>8} "
          f"{'make':>8} {'total':>8}  outcome")  # fmt: skip
    for r in range(1, args.rounds + 1):
        for side, commit in sides.items():
            row = one_round(commit, args.target, args.keep, args.quick) | {"side": side, "round": r}
            rows.append(row)
            print(
                f"{r:>5} {side:>8} {commit:>8} {row['load']:>5.2f} {row['install']:>7.1f}s "
                f"{row['run']:>7.1f}s {row['total']:>7.1f}s  {row['outcome']}"
                + ("" if row["rc"] == 0 else f" (exit {row['rc']})"),
                flush=True,
            )
    print("\nmedians (s):")
    for side, commit in sides.items():
        mine = [x for x in rows if x["side"] == side]
        parts = "  ".join(
            f"{k} {median(x[k] for x in mine):.1f}" for k in ("install", "run", "total")
        )
        print(f"{side:>8} {commit:>8}  {parts}")
    return 0 if all(x["rc"] == 0 for x in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
