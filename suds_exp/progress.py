"""Rich progress bars that a caller can switch off (scripts, tests, --quiet)."""

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
    """Items per second, e.g. ``3.20 jobs/s``."""

    def __init__(self, unit: str):
        super().__init__()
        self.unit = unit

    def render(self, task) -> Text:
        speed = task.finished_speed or task.speed
        return Text(f"-- {self.unit}/s" if speed is None else f"{speed:.2f} {self.unit}/s")


def progress_lines(enabled: bool = True) -> Callable[[str], None]:
    """``say(line)`` for work that reports stages rather than counts: prints each line on
    stderr when enabled (the switch a function's ``progress`` parameter sets), else
    nothing."""
    if not enabled:
        return lambda _line: None
    return lambda line: console.err.print(line, markup=False, highlight=False)


@contextmanager
def progress_bar(
    label: str, total: int, enabled: bool = True, done: int = 0, unit: str = "items"
) -> Iterator[Callable[[int], None]]:
    """Yield ``advance(n=1)``; draws a bar with rate and time left on stderr when enabled.

    The bar starts at ``done`` of ``total``, so resumed work shows its real state; rate
    and time left are measured on this run's items only. Nothing is drawn when stderr is
    not a terminal (scripts, pipes, CI logs); set FORCE_TERMINAL=1 to draw anyway.
    """
    if not enabled or not console.err.is_terminal:
        yield lambda n=1: None
        return
    columns = (
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        _RateColumn(unit),
        TimeElapsedColumn(),
        TextColumn("eta"),
        TimeRemainingColumn(),
    )
    with Progress(*columns, console=console.err, transient=False, speed_estimate_period=120) as bar:
        task = bar.add_task(label, total=total, completed=done)
        yield lambda n=1: bar.advance(task, n)
