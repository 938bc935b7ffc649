"""The campaign progress bar: jobs done of all jobs, rate in jobs/s, time left."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager

from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    ProgressColumn,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.text import Text

from suds_exp import console


class _RateColumn(ProgressColumn):
    def render(self, task) -> Text:
        speed = task.finished_speed or task.speed
        return Text("-- jobs/s" if speed is None else f"{speed:.2f} jobs/s")


@contextmanager
def job_progress(
    label: str, total: int, done: int, enabled: bool = True
) -> Iterator[Callable[[int], None]]:
    """Yield ``advance(n)``; draws the bar on stderr when ``enabled``.

    The bar starts at ``done`` of ``total`` so a resumed campaign shows its real state;
    rate and time left are measured on this run's jobs only.
    """
    if not enabled:
        yield lambda n=1: None
        return
    columns = (
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        _RateColumn(),
        TimeElapsedColumn(),
        TextColumn("eta"),
        TimeRemainingColumn(),
    )
    with Progress(*columns, console=console.err, transient=False, speed_estimate_period=120) as bar:
        task = bar.add_task(label, total=total, completed=done)
        yield lambda n=1: bar.advance(task, n)
