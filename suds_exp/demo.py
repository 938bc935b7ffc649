"""`suds-exp demo`: the whole pipeline on the built-in simulated robot.

simulate the paper's design (5 gaits x 3 frequencies x 4 repeats) into a temporary
folder -> ingest it -> preprocess -> a small bootstrap campaign with all five learners ->
its report. Every step is idempotent: a second run finds the data stored, the version
made and the campaign finished, and only rewrites the report.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from suds_exp.progress import progress_bar
from suds_exp.store import Store


@dataclass
class DemoSummary:
    """What the demo did: counts, the report's path, and seconds per step."""

    n_trials: int = 0
    simulated_seconds: float = 0.0
    prep_version: str = ""
    explained_variance: list[float] = field(default_factory=list)
    campaign: str = ""
    n_results: int = 0
    report: Path | None = None
    discrepancy: dict = field(default_factory=dict)
    seconds: dict[str, float] = field(default_factory=dict)


def run_demo(
    store: Store,
    report_dir: Path = Path("reports"),
    campaign: str = "demo",
    jobs: int = 2,
    seed: int = 0,
    progress: bool = True,
    say: Callable[[str], None] = print,
) -> DemoSummary:
    """Run the demo end to end into ``store``; returns a `DemoSummary`.

    ``report_dir / campaign`` receives the campaign report. ``say`` gets one line per
    finished step.
    """
    from suds_exp.analysis import write_report
    from suds_exp.campaign.demo import demo_campaign
    from suds_exp.ingest import ingest_paths
    from suds_exp.preprocess import preprocess
    from suds_exp.sim import simulate_dataset

    summary = DemoSummary(campaign=campaign)
    clock = time.perf_counter()

    def lap(step: str) -> float:
        nonlocal clock
        now = time.perf_counter()
        summary.seconds[step] = now - clock
        clock = now
        return summary.seconds[step]

    with tempfile.TemporaryDirectory(prefix="suds-demo-") as tmp:
        with progress_bar("Simulating", total=60, enabled=progress) as advance:
            data = simulate_dataset(tmp, seed=seed, progress=lambda done, total: advance())
        summary.simulated_seconds = data.simulated_seconds
        say(
            f"simulated {len(data.tsv_paths)} trials ({data.simulated_seconds / 60:.0f} min of "
            f"robot time) in {lap('simulate'):.0f} s"
        )
        results = ingest_paths(store, [Path(tmp)], manifest=data.manifest, progress=progress)
        summary.n_trials = len(results)
        fresh = sum(r.status == "ingested" for r in results)
        stored = len(results) - fresh
        say(f"ingested {fresh} new trials ({stored} already stored) in {lap('ingest'):.0f} s")

    prep = preprocess(store, progress=progress)
    summary.prep_version = prep.name
    summary.explained_variance = prep.explained_variance_ratio
    say(
        f"preprocessing version {prep.name}: {len(prep.processed)} trials processed, "
        f"{len(prep.skipped)} already done; passive PCs explain "
        f"{100 * sum(prep.explained_variance_ratio):.0f}% of the variance "
        f"({lap('preprocess'):.0f} s)"
    )

    run = demo_campaign(store, campaign, prep=prep.name, jobs=jobs, progress=progress)
    summary.n_results = run.done_before + run.done_now
    say(
        f"campaign {campaign!r}: {summary.n_results} of {run.total_jobs} jobs done "
        f"({lap('campaign'):.0f} s)"
    )

    summary.report = write_report(store, campaign, report_dir / campaign)
    say(f"report written to {summary.report} ({lap('report'):.0f} s)")
    return summary
