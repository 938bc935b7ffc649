"""Reliability probe: every writing command killed, raced, fed bad input, as a user would.

Runs `suds-exp` as separate processes on a small synthetic dataset (2 gaits x 2 repeats
of 12 cycles) and counts:

- kill -9: each writing command (ingest, preprocess, stream, run on loky and on dask,
  discrepancy) killed with SIGKILL to its main process at several moments, then run again
  to the end; "resumed identically" = every table it writes equals an uninterrupted run's
  (timings and timestamps aside), and no worker process of the killed one is alive 10 s
  later;
- two writers: every pair of writing commands (init, ingest, preprocess, stream, run,
  discrepancy; a command with itself too) started at several offsets on one database;
  "safe" = no traceback, each exits 0 or with one line (status 2), and no key is stored
  twice (SQL over every unique key);
- Ctrl-C: SIGINT to the process group of a running campaign (loky and dask): one line,
  status 130, no traceback;
- bad inputs: refused options, damaged files (cut at a 4 KiB boundary, a corrupted
  block), a read-only file system (a read-only tmpfs mount, when this process may mount),
  unwritable report and plot folders: one line, status 2, the database file byte-identical;
- the cost of the integrity check on a large file.

    python -m suds_exp.testing.reliability_probe            # the long version (~15 min on 2 cores)
    python -m suds_exp.testing.reliability_probe --quick    # one moment / offset each (~4 min)

`tests/test_reliability.py` runs its cases in parts. It drives the command line only, so it
sits in this box although the commands it runs reach every box above it.
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as dt
import hashlib
import itertools
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import duckdb
import pandas as pd

#: The command line of the suds_exp this module belongs to (a checkout's cli.py, an
#: installed wheel's app), whatever folder a command runs in: `ENV` puts that package first.
CLI = [sys.executable, "-m", "suds_exp"]
_TOP = str(Path(__file__).resolve().parents[2])
ENV = {
    **os.environ,
    "PYTHONPATH": os.pathsep.join(filter(None, [_TOP, os.environ.get("PYTHONPATH")])),
}
#: Columns that differ between two runs of the same work (clock, pid, timing).
VOLATILE = {
    "created_at",
    "fitted_at",
    "done_at",
    "ingested_at",
    "finished_at",
    "started_at",
    "seconds",
    "cpu_seconds",
    "fit_seconds",
    "predict_seconds",
    "learn_seconds",
    "report_dir",
}
#: Tables that record each invocation (so differ in row count between 1 and 2 runs).
PER_INVOCATION = {"schema_migrations", "campaign_runs"}
#: (table, key columns) that must never hold a duplicate.
KEYS = [
    ("trials", "content_hash"),
    ("prep_versions", "params_hash"),
    ("prep_versions", "name"),
    ("prep_trials", "version_id, trial_id"),
    ("samples", "version_id, trial_id, frame"),
    ("campaigns", "name"),
    (
        "results",
        "campaign, model, train_gait, train_frequency_hz, test_gait, test_frequency_hz, "
        "boot, n_cycles",
    ),
    ("streams", "name"),
    ("stream_cycles", "stream, model, trial_id, cycle"),
    ("discrepancy_runs", "name"),
]
SLOW_RUN = ["--models", "GMR", "--boots", "6", "--train-cycles", "3", "--jobs", "2"]


@dataclass
class Data:
    """The probe's files: synthetic captures, their manifest and three databases."""

    work: Path
    captures: Path
    manifest: Path
    ingested: Path
    prepped: Path

    def commands(self, tag: str = "") -> dict[str, tuple[Path | None, list[str]]]:
        """Writing command -> (database it starts from, None: none; its arguments)."""
        out = self.work / f"reports{tag}"
        return {
            "init": (self.ingested, ["init"]),
            "ingest": (None, ["ingest", str(self.captures), "--manifest", str(self.manifest)]),
            "preprocess": (self.ingested, ["preprocess", "--name", "v1"]),
            "stream": (self.prepped, ["stream", "s", "--models", "GMR,OnlineGMR", "--warmup", "3"]),
            "run": (self.prepped, ["run", "c", *SLOW_RUN]),
            "run-dask": (self.prepped, ["run", "c", *SLOW_RUN, "--backend", "dask"]),
            "discrepancy": (
                self.prepped,
                [
                    "discrepancy",
                    "--name",
                    "d",
                    "--out",
                    str(out / "d"),
                    "--max-effects",
                    "1",
                    "--no-discover",
                ],
            ),
        }


def build(work: Path) -> Data:
    """Write the synthetic captures and the ingested / preprocessed databases (through the
    command line, as a user would)."""
    from suds_exp.testing.synthetic_captures import write_dataset

    manifest = write_dataset(
        work / "captures", gaits=("O", "S+"), frequencies=(1.0,), repeats=2, n_cycles=12
    )
    ingested, prepped = work / "ingested.duckdb", work / "prepped.duckdb"
    _done(run(["ingest", str(manifest.parent), "--manifest", str(manifest)], ingested, work))
    shutil.copy(ingested, prepped)
    _done(run(["preprocess", "--name", "v1"], prepped, work))
    return Data(work, manifest.parent, manifest, ingested, prepped)


def _done(outcome: Outcome) -> None:
    if outcome.code != 0:
        raise RuntimeError(f"building the probe's data failed: {outcome.stderr[-500:]}")


# -- running commands -----------------------------------------------------------------------
@dataclass
class Outcome:
    code: int
    stdout: str
    stderr: str
    seconds: float
    orphans: int = 0
    orphan_seconds: float = 0.0

    @property
    def traceback(self) -> bool:
        text = self.stdout + self.stderr
        return "Traceback" in text or "KeyboardInterrupt" in text

    @property
    def one_line(self) -> bool:
        return len([x for x in self.stderr.splitlines() if x.strip()]) == 1


def start(args: list[str], db: Path, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen(
        [*CLI, *args, "--db", str(db), "-q"] if _quiet(args) else [*CLI, *args, "--db", str(db)],
        cwd=cwd,
        env=ENV,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def _quiet(args: list[str]) -> bool:
    return args[0] in ("ingest", "preprocess", "stream", "run", "discrepancy")


def finish(p: subprocess.Popen, started: float, timeout: float = 300) -> Outcome:
    out, err = p.communicate(timeout=timeout)
    return Outcome(p.returncode, out, err, time.perf_counter() - started)


def run(args: list[str], db: Path, cwd: Path) -> Outcome:
    t = time.perf_counter()
    return finish(start(args, db, cwd), t)


def descendants(pid: int) -> set[int]:
    """Every process below ``pid`` (Linux /proc)."""
    children: dict[int, list[int]] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    out, todo = set(), [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            if c not in out:
                out.add(c)
                todo.append(c)
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def kill9(p: subprocess.Popen, started: float, grace_s: float = 10.0) -> Outcome:
    """SIGKILL to the main process only; then how many of its descendants outlive it
    ``grace_s`` s, and how long the last of them took to go."""
    below = descendants(p.pid)
    os.kill(p.pid, signal.SIGKILL)
    t0 = time.perf_counter()
    p.wait()
    while any(_alive(c) for c in below) and time.perf_counter() - t0 < grace_s:
        time.sleep(0.1)
    left = [c for c in below if _alive(c)]
    gone = time.perf_counter() - t0
    for c in left:  # not ours to leave behind
        with contextlib.suppress(OSError):
            os.kill(c, signal.SIGKILL)
    # (returns once every process holding the pipes is gone: workers inherit them)
    out, err = p.communicate()
    return Outcome(p.returncode, out, err, time.perf_counter() - started, len(left), gone)


# -- database checks ---------------------------------------------------------------------------
def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest() if path.exists() else "absent"


def dump(db: Path) -> dict[str, pd.DataFrame]:
    """Every table, volatile columns dropped, rows sorted."""
    out = {}
    con = duckdb.connect(str(db), read_only=True)
    try:
        names = [r[0] for r in con.execute("SELECT table_name FROM duckdb_tables()").fetchall()]
        for name in sorted(set(names) - PER_INVOCATION):
            frame = con.execute(f'SELECT * FROM "{name}"').df()
            frame = frame.drop(columns=[c for c in frame.columns if c in VOLATILE])
            key = [c for c in frame.columns if frame[c].map(_sortable).all()]
            if key:
                frame = frame.sort_values(key, kind="stable")
            out[name] = frame.reset_index(drop=True)
    finally:
        con.close()
    return out


def _sortable(v) -> bool:
    return isinstance(v, str | int | float | bool) or v is None


def same(a: dict[str, pd.DataFrame], b: dict[str, pd.DataFrame]) -> bool:
    if a.keys() != b.keys():
        return False
    for name in a:
        x, y = a[name], b[name]
        if x.shape != y.shape or list(x.columns) != list(y.columns):
            return False
        if not x.astype(str).equals(y.astype(str)):
            return False
    return True


def duplicates(db: Path) -> list[str]:
    """``table(key)`` for every key of `KEYS` that holds a value twice."""
    if not db.exists():
        return []
    con = duckdb.connect(str(db), read_only=True)
    try:
        have = {r[0] for r in con.execute("SELECT table_name FROM duckdb_tables()").fetchall()}
        bad = []
        for table, key in KEYS:
            if table not in have:
                continue
            n = con.execute(f"SELECT count(*) - count(DISTINCT ({key})) FROM {table}").fetchone()[0]
            if n:
                bad.append(f"{table}({key}): {n} duplicates")
        return bad
    finally:
        con.close()


# -- the four probes ------------------------------------------------------------------------------
@dataclass
class Tally:
    name: str
    ok: int = 0
    total: int = 0
    failures: list[str] = field(default_factory=list)

    def add(self, ok: bool, what: str) -> None:
        self.total += 1
        self.ok += bool(ok)
        if not ok:
            self.failures.append(what)
            print(f"  FAIL {self.name}: {what}", flush=True)


def fresh(base: Path | None, folder: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    db = folder / "suds.duckdb"
    for old in folder.glob("suds.duckdb*"):
        old.unlink()
    if base is not None:
        shutil.copy(base, db)
    return db


def probe_kill(data: Data, moments: list[float], names: list[str]) -> tuple[Tally, Tally]:
    """kill -9 each command at ``moments`` (fractions of its uninterrupted duration) and
    resume it; returns (resumed identically, no worker left after 10 s)."""
    resumed, orphans = Tally("kill -9"), Tally("workers gone 10 s after kill -9")
    for name in names:
        base, args = data.commands()[name]
        folder = data.work / f"kill-{name}-ref"
        ref_db = fresh(base, folder)
        ref = run(args, ref_db, folder)
        if ref.code != 0:
            resumed.add(False, f"{name}: the uninterrupted run failed: {ref.stderr[-300:]}")
            continue
        expected = dump(ref_db)
        for i, frac in enumerate(moments):
            folder = data.work / f"kill-{name}-{i}"
            for tries in range(3):
                # a run faster than the reference ends before the kill: earlier then
                at = frac * ref.seconds * (0.8**tries)
                db = fresh(base, folder)
                t = time.perf_counter()
                p = start(args, db, folder)
                time.sleep(at)
                if p.poll() is None:
                    break
                finish(p, t)
            else:
                resumed.add(False, f"{name} at {frac:.0%}: ended before the kill 3 times")
                continue
            killed = kill9(p, t)
            orphans.add(
                killed.orphans == 0,
                f"{name} at {frac:.0%}: {killed.orphans} processes alive 10 s after kill -9",
            )
            again = run(args, db, folder)
            # a kill after the last commit leaves the work stored: a discrepancy run's
            # name is then taken, and the rerun says so in one line
            done = again.code == 0 or (again.code == 2 and again.one_line)
            ok = done and not again.traceback and same(dump(db), expected)
            resumed.add(ok, f"{name} at {frac:.0%}: rc {again.code} {again.stderr[-300:]}")
            print(
                f"  kill -9 {name} at {at:.1f} s ({ref.seconds:.1f} s uninterrupted): resumed "
                f"{'identically' if ok else 'DIFFERENTLY'}; workers gone after "
                f"{killed.orphan_seconds:.1f} s",
                flush=True,
            )
    return resumed, orphans


def probe_pairs(data: Data, offsets: list[float], names: list[str]) -> Tally:
    """Two writers on one database, the second started ``offset`` s after the first."""
    tally = Tally("two writers")
    # a command with itself first: the races that stored rows twice before
    pairs = [(n, n) for n in names] + list(itertools.combinations(names, 2))
    for (a, b), offset in itertools.product(pairs, offsets):
        cmds_a, cmds_b = data.commands("a"), data.commands("b")
        base_a, args_a = cmds_a[a]
        base_b, args_b = cmds_b[b]
        if a == b == "discrepancy":
            args_b = cmds_a[b][1]  # the same name and report folder
        base = data.prepped if data.prepped in (base_a, base_b) else (base_a or base_b)
        folder = data.work / f"pair-{a}-{b}-{offset:g}"
        db = fresh(base, folder)
        t = time.perf_counter()
        pa = start(args_a, db, folder)
        time.sleep(offset)
        pb = start(args_b, db, folder)
        ra, rb = finish(pa, t), finish(pb, t)
        dup = duplicates(db)
        ok = (
            not dup
            and all(not r.traceback for r in (ra, rb))
            and all(r.code == 0 or (r.code == 2 and r.one_line) for r in (ra, rb))
        )
        tally.add(
            ok,
            f"{a} + {b} at {offset:g} s: rc {ra.code}/{rb.code} {dup} "
            f"{ra.stderr[-200:]} | {rb.stderr[-200:]}",
        )
        print(
            f"  {a} + {b} (+{offset:g} s): rc {ra.code}, {rb.code}; "
            f"{'no duplicate' if not dup else dup}",
            flush=True,
        )
    return tally


def campaign_args(backend: str, boots: int = 12) -> list[str]:
    """A GMR campaign of ``boots`` x 4 jobs on 2 workers of ``backend`` (loky, dask)."""
    return ["run", "c", "--models", "GMR", "--boots", str(boots), "--train-cycles", "3",
            "--jobs", "2", "--backend", backend]  # fmt: skip


def probe_ctrl_c(data: Data) -> Tally:
    """SIGINT to the process group of a running campaign (a terminal's Ctrl-C)."""
    tally = Tally("Ctrl-C")
    for backend in ("loky", "dask"):
        folder = data.work / f"ctrl-c-{backend}"
        db = fresh(data.prepped, folder)
        args = campaign_args(backend)
        t = time.perf_counter()
        p = start(args, db, folder)
        deadline = time.perf_counter() + 60
        while len(descendants(p.pid)) < 2 and time.perf_counter() < deadline:
            time.sleep(0.2)
        time.sleep(2.0)
        r, presses = ctrl_c(p, t)
        lines = [x for x in (r.stdout + r.stderr).splitlines() if x.strip()]
        ok = r.code == 130 and not r.traceback and len(lines) == 1 and "stopped" in lines[0]
        tally.add(ok, f"{backend}: rc {r.code}, {len(lines)} lines: {(r.stdout + r.stderr)[-400:]}")
        print(
            f"  Ctrl-C {backend} ({presses} press{'es' if presses > 1 else ''}): rc {r.code}, "
            f"{len(lines)} line(s): {lines[:1]}",
            flush=True,
        )
    return tally


def ctrl_c(p: subprocess.Popen, started: float, again_s: float = 3.0) -> tuple[Outcome, int]:
    """SIGINT to ``p``'s process group, as a terminal's Ctrl-C; pressed again when the
    process still runs ``again_s`` s later (a Ctrl-C while workers start may be lost:
    see `suds_exp.campaign.signals.sigint_blocked`). Returns the outcome and the presses."""
    presses = 0
    while True:
        os.killpg(p.pid, signal.SIGINT)
        presses += 1
        try:
            p.wait(timeout=again_s)
        except subprocess.TimeoutExpired:
            continue
        return finish(p, started), presses


def _damaged_copies(data: Data, folder: Path) -> dict[str, Path]:
    from suds_exp.store.integrity import HEADER_BYTES, free_blocks, read_header

    folder.mkdir(parents=True, exist_ok=True)
    raw = data.prepped.read_bytes()
    cut = folder / "cut.duckdb"
    cut.write_bytes(raw[: len(raw) // 2 // 4096 * 4096])
    count, size, pointer = read_header(data.prepped, raw[:HEADER_BYTES], len(raw))
    with data.prepped.open("rb") as f:
        free = free_blocks(data.prepped, f, count, size, pointer)
    used = [b for b in range(count) if b not in free]
    block = used[len(used) // 2]
    at = HEADER_BYTES + block * size + size // 2
    bad = bytearray(raw)
    # random bytes (flipping zeros would cancel out in DuckDB's xor-of-words checksum)
    bad[at : at + 64] = random.Random(block).randbytes(64)
    corrupt = folder / "corrupt.duckdb"
    corrupt.write_bytes(bytes(bad))
    return {"cut at a 4 KiB boundary": cut, "a corrupted block": corrupt}


@contextlib.contextmanager
def read_only_mount(source: Path):
    """A read-only tmpfs holding a copy of ``source``'s folder; None when this process
    may not mount (not root, no tmpfs)."""
    point = Path(tempfile.mkdtemp(prefix="suds-ro-"))
    try:
        subprocess.run(
            ["mount", "-t", "tmpfs", "-o", "size=64m", "tmpfs", str(point)],
            check=True,
            capture_output=True,
        )
    except (OSError, subprocess.CalledProcessError):
        point.rmdir()
        yield None
        return
    try:
        shutil.copy(source, point / "suds.duckdb")
        (point / "reports").mkdir()
        subprocess.run(["mount", "-o", "remount,ro", str(point)], check=True, capture_output=True)
        yield point
    finally:
        subprocess.run(["umount", str(point)], capture_output=True)
        point.rmdir()


def every_command(data: Data, folder: Path) -> list[list[str]]:
    """One call of every command that opens the database (reports go under ``folder``)."""
    return [
        ["trials"],
        ["status", "c"],
        ["sql", "SELECT count(*) FROM trials"],
        ["init"],
        ["ingest", str(data.captures), "--manifest", str(data.manifest)],
        ["preprocess"],
        ["run", "c", "--models", "TLS", "--boots", "1"],
        ["stream", "s"],
        ["discrepancy", "--out", str(folder / "dd")],
        ["report", "c", "--out", str(folder / "rr")],
        ["findings", "c"],
    ]


def probe_bad_inputs(data: Data) -> tuple[Tally, int]:
    """Refused inputs: one line, status 2, the database byte-identical (and names free)."""
    tally = Tally("bad inputs")
    folder = data.work / "bad"
    db = fresh(data.prepped, folder)
    blocker = folder / "a-file"
    blocker.write_text("in the way of a folder\n")
    refusals = [
        ["run", "c", "--model-param", "GMR.n_components=abc"],
        ["run", "c", "--backend", "dask", "--scheduler", "tcp://127.0.0.1:1"],
        ["run", "c", "--models", "TLS,nope"],
        ["run", "c", "--boots", "0"],
        ["stream", "s", "--models", "GMR,GradualGMR+SUDS", "--warmup", "3"],
        ["stream", "s", "--change-at", "-5"],
        ["stream", "s", "--change-at", "abc"],
        ["stream", "s", "--change-at", "1000"],
        ["stream", "s", "--trials", "99"],
        ["stream", "s", "--plot", str(blocker / "x.png")],
        ["findings", "c", "--boot", "0"],
        ["preprocess", "--param", "k=abc"],
        ["preprocess", "--trials", "99"],
        ["discrepancy", "--alpha", "2"],
        ["discrepancy", "--out", str(blocker / "d")],
        ["report", "c", "--out", str(blocker / "r")],
        ["ingest", str(folder / "missing.tsv")],
    ]
    cases = [(args, db) for args in refusals]
    everyone = every_command(data, folder)
    for copy in _damaged_copies(data, folder / "damaged").values():
        cases += [(args, copy) for args in everyone]
    for args, path in cases:
        before = digest(path)
        r = run(args, path, folder)
        ok = r.code == 2 and r.one_line and not r.traceback and digest(path) == before
        tally.add(ok, f"{' '.join(args)} on {path.name}: rc {r.code} {r.stderr[-300:]}")
    ro_cases = 0
    with read_only_mount(data.prepped) as point:
        if point is not None:
            ro_db = point / "suds.duckdb"
            outside = fresh(data.prepped, folder / "outside")
            ro = [
                (["init"], ro_db),
                (["ingest", str(data.captures), "--manifest", str(data.manifest)], ro_db),
                (["preprocess", "--name", "v2", "--param", "k=3"], ro_db),
                (["run", "c", "--models", "TLS", "--boots", "1"], ro_db),
                (["stream", "s"], ro_db),
                (["discrepancy", "--out", str(folder / "ro-d")], ro_db),
                (["report", "c", "--out", str(point / "reports" / "c")], outside),
                (["discrepancy", "--out", str(point / "reports" / "d")], outside),
                (["stream", "s", "--plot", str(point / "reports" / "s.png")], outside),
            ]
            for args, path in ro:
                before = digest(path)
                r = run(args, path, folder)
                ok = r.code == 2 and r.one_line and not r.traceback and digest(path) == before
                tally.add(ok, f"read-only: {' '.join(args)}: rc {r.code} {r.stderr[-300:]}")
            ro_cases = len(ro)
    return tally, ro_cases


def integrity_cost(work: Path, rows: int = 10_000_000) -> tuple[float, float]:
    """(MB, median s of 3) of the full block check on a file of ``rows`` x 4 random doubles."""
    from suds_exp.store.integrity import _verified, check_file

    path = work / "large.duckdb"
    con = duckdb.connect(str(path), config={"storage_compatibility_version": "v1.4.0"})
    con.execute(
        f"CREATE TABLE t AS SELECT random() a, random() b, random() c, random() d "
        f"FROM range({rows})"
    )
    con.close()
    times = []
    for _ in range(3):
        _verified.clear()
        t = time.perf_counter()
        check_file(path)
        times.append(time.perf_counter() - t)
    return path.stat().st_size / 1e6, sorted(times)[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one moment and offset each")
    ap.add_argument("--work", type=Path, help="folder to work in (default: a temporary one)")
    ap.add_argument("--only", help="comma list of kill,pairs,ctrl-c,bad,integrity")
    opts = ap.parse_args()
    only = set((opts.only or "kill,pairs,ctrl-c,bad,integrity").split(","))
    moments = [0.5] if opts.quick else [0.25, 0.5, 0.8]
    offsets = [1.4] if opts.quick else [0.0, 0.7, 1.4]
    with contextlib.ExitStack() as stack:
        work = opts.work or Path(stack.enter_context(tempfile.TemporaryDirectory()))
        work.mkdir(parents=True, exist_ok=True)
        started = time.perf_counter()
        data = build(work)
        lines = []
        if "kill" in only:
            names = ["ingest", "preprocess", "stream", "run", "run-dask", "discrepancy"]
            resumed, orphans = probe_kill(data, moments, names)
            lines.append(f"kill -9: {resumed.ok} of {resumed.total} resumed identically")
            lines.append(
                f"kill -9 of the main process: {orphans.ok} of {orphans.total} left no "
                "worker alive after 10 s"
            )
        if "pairs" in only:
            names = ["init", "ingest", "preprocess", "stream", "run", "discrepancy"]
            pairs = probe_pairs(data, offsets, names)
            lines.append(f"two writers: {pairs.ok} of {pairs.total} safe")
        if "ctrl-c" in only:
            c = probe_ctrl_c(data)
            lines.append(f"Ctrl-C to the process group: {c.ok} of {c.total} one line, status 130")
        if "bad" in only:
            bad, ro = probe_bad_inputs(data)
            lines.append(
                f"bad inputs: {bad.ok} of {bad.total} one line with the database unchanged"
                + (f" ({ro} on a read-only file system)" if ro else " (no read-only mount)")
            )
        if "integrity" in only:
            mb, s = integrity_cost(work)
            lines.append(f"integrity check of a {mb:.0f} MB file: {s:.2f} s (median of 3)")
        print()
        print(
            f"reliability probe, {dt.datetime.now(dt.UTC):%Y-%m-%d %H:%M} UTC, "
            f"{'quick' if opts.quick else 'full'}, {time.perf_counter() - started:.0f} s"
        )
        for line in lines:
            print(line)


if __name__ == "__main__":
    main()
