"""`suds-exp demo`: the whole pipeline on the built-in simulated robot.

Simulate the paper's design (5 gaits x 3 frequencies x 4 repeats) into a temporary
folder -> ingest it -> preprocess -> a small bootstrap campaign with all five learners ->
its report and the paper's findings measured on it -> a discrepancy run on new data with
one effect hidden in it. Every step is idempotent: a second run finds the data stored, the
version made and the campaign finished, and only rewrites the reports.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from suds_exp.errors import IngestError
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
    findings: list[dict] = field(default_factory=list)
    findings_headline: str = ""
    passive_information: list[dict] = field(default_factory=list)
    discrepancy: dict = field(default_factory=dict)
    discrepancy_report: Path | None = None
    seconds: dict[str, float] = field(default_factory=dict)


def _fmt(value) -> str:
    return f"{value:.3g}" if isinstance(value, float) else str(value)


def run_demo(
    store: Store,
    report_dir: Path = Path("reports"),
    campaign: str = "demo",
    jobs: int = 2,
    seed: int = 0,
    hidden_effect: str = "body_inertia",
    progress: bool = True,
    say: Callable[[str], None] | None = None,
) -> DemoSummary:
    """Run the demo end to end into ``store``; returns a `DemoSummary`.

    ``report_dir / campaign`` receives the campaign report and
    ``report_dir / "discrepancy-demo"`` the discrepancy report of ``hidden_effect``
    hidden in new simulated data. ``progress``: bars and stage lines on stderr;
    ``say``: called with one line of text per finished step (the demo's narration;
    the command prints it), None: silent.
    """
    from suds_exp.analysis import write_report
    from suds_exp.workflows.demo_campaign import demo_campaign

    say = say or (lambda _line: None)
    summary = DemoSummary(campaign=campaign)
    lap = _Clock(summary).lap
    simulate_step(store, summary, seed, progress, say, lap)
    prep_name = preprocess_step(store, summary, progress, say, lap)
    run = demo_campaign(store, campaign, prep=prep_name, jobs=jobs, progress=progress)
    summary.n_results = run.done_before + run.done_now
    say(
        f"campaign {campaign!r}: {summary.n_results} of {run.total_jobs} jobs done "
        f"({lap('campaign'):.0f} s)"
    )
    summary.report = write_report(store, campaign, report_dir / campaign)
    say(f"report written to {summary.report} ({lap('report'):.0f} s)")
    findings_step(store, summary, say, lap)
    discrepancy_step(summary, report_dir / "discrepancy-demo", hidden_effect, seed, say, lap)
    return summary


class _Clock:
    """``lap(step)``: seconds since the previous lap, recorded in the summary."""

    def __init__(self, summary: DemoSummary):
        self.summary, self.clock = summary, time.perf_counter()

    def lap(self, step: str) -> float:
        now = time.perf_counter()
        self.summary.seconds[step] = now - self.clock
        self.clock = now
        return self.summary.seconds[step]


def simulate_step(store: Store, summary: DemoSummary, seed: int, progress, say, lap):
    """Simulate the paper's design into a temporary folder and ingest it."""
    from suds_exp.sim.dataset import SimDesign
    from suds_exp.workflows.simulate import simulate_and_ingest

    with tempfile.TemporaryDirectory(prefix="suds-demo-") as tmp:
        try:
            run = simulate_and_ingest(store, tmp, design=SimDesign(seed=seed), progress=progress)
        except IngestError as exc:
            # e.g. a database holding another dataset (or an older simulator's) at the
            # same conditions: never overwrite it, say how to run the demo anyway.
            raise IngestError(
                f"{exc} -- the demo's simulated trials clash with trials already in "
                f"{store.path}; run the demo on a database of its own, e.g. demo.duckdb"
            ) from None
    data = run.dataset
    summary.simulated_seconds = data.simulated_seconds
    summary.n_trials = len(run.ingested)
    both = lap("ingest")
    summary.seconds["simulate"] = run.wall_seconds
    summary.seconds["ingest"] = both - run.wall_seconds
    say(
        f"simulated {len(data.tsv_paths)} trials ({data.simulated_seconds / 60:.0f} min of "
        f"robot time) in {run.wall_seconds:.0f} s"
    )
    say(
        f"ingested {run.n_new} new trials ({summary.n_trials - run.n_new} already stored) "
        f"in {summary.seconds['ingest']:.0f} s"
    )


def preprocess_step(store: Store, summary: DemoSummary, progress, say, lap) -> str:
    """Preprocess with the default parameters; the version's name."""
    from suds_exp.preprocess import preprocess

    prep = preprocess(store, progress=progress)
    summary.prep_version = prep.name
    summary.explained_variance = prep.explained_variance_ratio
    say(
        f"preprocessing version {prep.name}: {len(prep.processed)} trials processed, "
        f"{len(prep.skipped)} already done; passive PCs explain "
        f"{100 * sum(prep.explained_variance_ratio):.0f}% of the variance "
        f"({lap('preprocess'):.0f} s)"
    )
    return prep.name


def findings_step(store: Store, summary: DemoSummary, say, lap) -> None:
    """The paper's findings measured on the demo campaign."""
    from suds_exp.analysis import findings
    from suds_exp.analysis.findings import findings_display, findings_headline, findings_json

    campaign = summary.campaign
    table = findings(store, campaign)  # the same table as the report's first section
    summary.findings = findings_json(table, campaign)["statistics"]
    summary.findings_headline = findings_headline(table)
    say(
        f"the paper's findings on this SMALL campaign ({table.attrs['n_results']} results, "
        f"{table.attrs['main_cycles']} training cycles; the paper's scale is `suds-exp run "
        "paper --sweep paper`, 21,000 jobs), each with a 95 % bootstrap interval:"
    )
    display = findings_display(table)
    say(display.to_string(index=False, max_colwidth=60))
    say(f"{summary.findings_headline} ({lap('findings'):.0f} s)")
    from suds_exp.analysis.passive import (
        PASSIVE_EXPLANATION,
        campaign_passive_information,
        passive_display,
    )

    passive = campaign_passive_information(store, campaign)
    summary.passive_information = passive.to_dict(orient="records")
    if not passive.empty:
        say("what the passive shape adds (out-of-sample RMS error of vx, mm/s):")
        say(passive_display(passive).to_string(index=False))
        say(PASSIVE_EXPLANATION)


def discrepancy_step(summary: DemoSummary, out: Path, hidden_effect: str, seed: int, say, lap):
    """Hide ``hidden_effect`` in new simulated data and let the workflow name it."""
    from suds_exp.workflows.hidden_effects import demo_discrepancy

    # The hidden-effect data lives in its own temporary database: it re-uses the
    # conditions of the demo's data with different content, which ingest would refuse.
    found = demo_discrepancy(effect=hidden_effect, seed=seed, out=out)
    summary.discrepancy = found
    summary.discrepancy_report = out / "index.html"
    hidden = ", ".join(
        f"{effect} ({', '.join(f'{p}={_fmt(v)}' for p, v in settings.items())})"
        for effect, settings in found["hidden"].items()
    )
    named = (
        ", ".join(
            f"{n['candidate']} = {n['value']:.3g} (95% CI {n['ci'][0]:.3g} to {n['ci'][1]:.3g})"
            if n.get("ci")
            else f"{n['candidate']} = {n['value']:.3g}"
            for n in found["named"]
        )
        or "nothing"
    )
    say(
        f"discrepancy: hid {hidden} in new simulated data; the workflow named {named}; "
        f"held-out RMS error of vx {found['rmse_vx_before']:.2f} -> "
        f"{found['rmse_vx_after']:.2f} mm/s ({lap('discrepancy'):.0f} s)"
    )
