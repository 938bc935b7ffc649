"""One campaign in-process, on 2 loky workers and on a real dask cluster over TCP, side by
side in one run: wall time, speed-up, each job's own fit+predict time, where the CPU time
of a dask run goes (the ``suds-exp run`` client, the scheduler, the workers), and whether
the rows agree.

Usage::

    .venv/bin/python -m benchmarks.speed.dask_scaling                  # a small dataset
    .venv/bin/python -m benchmarks.speed.dask_scaling --boots 15 --rounds 2    # ~2 min idle
    .venv/bin/python -m benchmarks.speed.dask_scaling --boots 60 --rounds 3 --workers 2
    .venv/bin/python -m benchmarks.speed.dask_scaling --worker-env OMP_NUM_THREADS=1

The dataset (4 conditions, 2 repeats of 10 cycles, simulated once into a temporary
folder, or ``--db``, a preprocessed database) is copied for every run. Each round runs,
in turn: ``suds-exp run`` in-process (``-j 1``), with loky (``-j 2``), and with
``--scheduler`` on a cluster this script starts on 127.0.0.1 (``dask scheduler`` and
``--workers`` separate ``dask worker --nthreads 1 --no-nanny --preload
suds_exp.campaign.dask_worker`` processes, 1 and 2 of them by default; ``--nanny`` keeps
dask's nanny process), stopped after each run.
``--worker-env`` sets environment variables of the dask workers only (to test what slows
them down). Figures are medians over ``--rounds`` (with more than one, each round's
speed-up is printed too); "wall" is the run's own time as ``run`` reports it (from the
campaign's start: the database opened, the samples loaded, the plan, the cluster joined,
the jobs, the last write), "proc" the ``suds-exp run`` process's wall time, its start-up
(Python, imports, options) included, each with its speed-up over in-process; "job" is a
job's ``fit_seconds +
predict_seconds`` as the results table stores it; "client CPU" is the ``suds-exp run``
process's CPU time (user + system, its start-up included: imports, samples, plan; ~3 s on
a 2-core machine) and its share of the CPU time of the client, the scheduler and the
workers together during the run (read from ``/proc``, so dask rows only, on Linux);
"all CPU" is the CPU time of the run's processes together (the client and its loky
workers; with dask, the client, the scheduler and the workers);
"tasks" is the number of campaign tasks the cluster ran and "task s" their median compute
time (the scheduler's task stream; a task is a batch of draws, see ``run_campaign``'s
``chunk_jobs``). ``--quick``: phase-only, one draw of 2 cycles, one dask worker (a smoke
run). ``--workers 2`` leaves the one-worker cluster out (a shorter run).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import resource
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from statistics import median

import duckdb

BIN = Path(sys.executable).parent


def _suds(*args: str) -> str:
    return _timed_suds(*args)[0]


def _timed_suds(*args: str) -> tuple[str, float]:
    """The output of ``suds-exp ARGS`` and the process's wall time, its start-up included."""
    t0 = time.perf_counter()
    out = subprocess.run([str(BIN / "suds-exp"), *args], capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(f"suds-exp {' '.join(args)}: {out.stderr.strip()}")
    return out.stdout, time.perf_counter() - t0


def _dataset(folder: Path) -> Path:
    db = folder / "base.duckdb"
    _suds(
        "simulate",
        "--out",
        str(folder / "sim"),
        "--gaits",
        "O,S+",
        "--freqs",
        "1/2,1",
        "--repeats",
        "2",
        "--cycles",
        "10",
        "--ingest",
        "--db",
        str(db),
        "-q",
    )
    _suds("preprocess", "--db", str(db), "-q")
    return db


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class _Cluster:
    """``dask scheduler`` and ``n`` ``dask worker --nthreads 1`` processes on 127.0.0.1."""

    def __init__(self, n: int, env: dict[str, str], nanny: bool = False):
        port = _free_port()
        self.address = f"tcp://127.0.0.1:{port}"
        quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
        self.scheduler = subprocess.Popen(
            [
                str(BIN / "dask"),
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                str(port),
                "--dashboard-address",
                "127.0.0.1:0",
            ],
            **quiet,
        )
        self.workers = [
            subprocess.Popen(
                [
                    str(BIN / "dask"),
                    "worker",
                    self.address,
                    "--nthreads",
                    "1",
                    *([] if nanny else ["--no-nanny"]),
                    "--host",
                    "127.0.0.1",
                    "--dashboard-address",
                    "127.0.0.1:0",
                    # as the how-to starts them: the learners imported before the run
                    "--preload",
                    "suds_exp.campaign.dask_worker",
                ],
                env={**os.environ, **env},
                **quiet,
            )
            for _ in range(n)
        ]
        from dask.distributed import Client

        with Client(self.address, timeout=30) as client:
            client.wait_for_workers(n, timeout=60)
            client.get_task_stream()  # the scheduler records every task from now on

    def tasks(self) -> list[float]:
        """Compute seconds of each campaign task the cluster ran (its task stream)."""
        from dask.distributed import Client

        with Client(self.address, timeout=30) as client:
            stream = client.get_task_stream()
        return [
            ss["stop"] - ss["start"]
            for t in stream
            if t["key"].startswith("run_chunk")
            for ss in t["startstops"]
            if ss["action"] == "compute"
        ]

    def stop(self) -> None:
        for p in [*self.workers, self.scheduler]:
            p.terminate()
        for p in [*self.workers, self.scheduler]:
            try:
                p.wait(timeout=5)
            except subprocess.TimeoutExpired:  # a worker may linger on SIGTERM
                p.kill()
                p.wait(timeout=30)


def _cpu_s(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` so far (Linux ``/proc``; NaN elsewhere)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
    except OSError:
        return float("nan")
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _run(
    base: Path, folder: Path, label: str, a, extra: list[str], cluster: _Cluster | None = None
) -> dict:
    db = folder / f"{label}.duckdb"
    shutil.copy(base, db)
    pids = [p.pid for p in [cluster.scheduler, *cluster.workers]] if cluster else []
    others = [_cpu_s(p) for p in pids]
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    args = [
        "run",
        "c",
        "--models",
        a.models,
        "--boots",
        str(a.boots),
        "--train-cycles",
        str(a.train_cycles),
        "--db",
        str(db),
        "--json",
        "-q",
        *extra,
    ]
    out, process = _timed_suds(*args)
    summary = json.loads(out)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    # the run's process and, with loky, its workers (reaped by it)
    client = (after.ru_utime + after.ru_stime) - (children.ru_utime + children.ru_stime)
    cluster_cpu = sum(_cpu_s(p) - c for p, c in zip(pids, others, strict=True))
    tasks = cluster.tasks() if cluster else []
    with duckdb.connect(str(db), read_only=True) as con:
        job = con.sql("SELECT median(fit_seconds + predict_seconds) FROM results").fetchone()[0]
        rows = con.sql(
            "SELECT * EXCLUDE (fit_seconds, predict_seconds, finished_at) FROM results ORDER BY ALL"
        ).df()
    db.unlink()
    digest = hashlib.sha256(rows.to_csv(index=False).encode()).hexdigest()[:12]
    return {
        "wall": summary["seconds"],
        "process": process,
        "job_ms": 1000 * job,
        "jobs": summary["total_jobs"],
        "digest": digest,
        "client_cpu": client,
        "share": client / (client + cluster_cpu) if cluster else float("nan"),
        "all_cpu": client + cluster_cpu,
        "tasks": len(tasks),
        "task_s": median(tasks) if tasks else float("nan"),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", type=Path, help="a preprocessed database (default: simulate one)")
    ap.add_argument("--models", default="phase-only,TLS,TLS+SUDS,GMR,GMR+SUDS")
    ap.add_argument("--boots", type=int, default=4)
    ap.add_argument("--train-cycles", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--workers", default="1,2", help="dask worker counts to run")
    ap.add_argument("--worker-env", action="append", default=[], metavar="NAME=VALUE")
    ap.add_argument("--nanny", action="store_true", help="workers under a nanny process")
    ap.add_argument("--quick", action="store_true", help="a smoke run at tiny sizes")
    a = ap.parse_args(argv)
    if a.quick:
        a.models, a.boots, a.train_cycles, a.workers, a.rounds = "phase-only", 1, 2, "1", 1
    began, load = time.perf_counter(), os.getloadavg()
    env = dict(item.split("=", 1) for item in a.worker_env)
    counts = [int(n) for n in a.workers.split(",")]
    with tempfile.TemporaryDirectory(prefix="suds-dask-") as tmp:
        folder = Path(tmp)
        base = a.db or _dataset(folder)
        runs: dict[str, list[dict]] = {}
        for _ in range(a.rounds):
            runs.setdefault("in-process", []).append(_run(base, folder, "one", a, ["-j", "1"]))
            runs.setdefault("loky -j 2", []).append(_run(base, folder, "loky", a, ["-j", "2"]))
            for n in counts:
                cluster = _Cluster(n, env, a.nanny)
                try:
                    r = _run(
                        base,
                        folder,
                        f"dask{n}",
                        a,
                        ["--backend", "dask", "--scheduler", cluster.address],
                        cluster,
                    )
                finally:
                    cluster.stop()
                runs.setdefault(f"dask TCP, {n} worker(s)", []).append(r)
    ref = runs["in-process"]
    ref_wall, ref_job = median(r["wall"] for r in ref), median(r["job_ms"] for r in ref)
    ref_process = median(r["process"] for r in ref)
    print(
        f"{ref[0]['jobs']} jobs ({a.models}; {a.boots} draws, {a.train_cycles} cycles), "
        f"{a.rounds} round(s), medians; worker env {env or 'default'}; "
        f"{'with' if a.nanny else 'no'} nanny; load average at the start "
        f"{load[0]:.1f}, at the end {os.getloadavg()[0]:.1f}; "
        f"{time.perf_counter() - began:.0f} s in all"
    )
    print(
        f"{'mode':22} {'wall s':>6} {'speed-up':>8} {'proc s':>6} {'speed-up':>8} "
        f"{'job ms':>6} {'job/in-proc':>11} {'client CPU s':>12} {'share':>6} {'all CPU s':>9} "
        f"{'tasks':>5} {'task s':>6}  rows"
    )
    for label, rs in runs.items():
        wall, job = median(r["wall"] for r in rs), median(r["job_ms"] for r in rs)
        process = median(r["process"] for r in rs)
        client, share = median(r["client_cpu"] for r in rs), median(r["share"] for r in rs)
        all_cpu = median(r["all_cpu"] for r in rs)
        share_text = f"{share:6.1%}" if share == share else f"{'':6}"
        tasks, task_s = median(r["tasks"] for r in rs), median(r["task_s"] for r in rs)
        task_text = f"{tasks:5.0f} {task_s:6.2f}" if tasks else f"{'':5} {'':6}"
        same = "same" if {r["digest"] for r in rs} == {ref[0]["digest"]} else "DIFFER"
        print(
            f"{label:22} {wall:6.1f} {ref_wall / wall:7.2f}x {process:6.1f} "
            f"{ref_process / process:7.2f}x {job:6.1f} {job / ref_job:10.2f}x "
            f"{client:12.2f} {share_text} {all_cpu:9.2f} {task_text}  {same}"
        )
    if a.rounds > 1:
        print("each round's speed-up (wall), in order:")
        for label, rs in runs.items():
            ups = " ".join(f"{r0['wall'] / r['wall']:.2f}x" for r0, r in zip(ref, rs, strict=True))
            print(f"  {label:20} {ups}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
