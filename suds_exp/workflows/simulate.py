"""Simulate a design and ingest its files, as a capture system's would be.

This is the one place that chains `suds_exp.sim` and `suds_exp.ingest`, which stay
independent of each other (an import-linter contract).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from suds_exp.errors import ConfigError
from suds_exp.robot import FREQUENCIES_HZ, GAITS
from suds_exp.sim.config import SimConfig
from suds_exp.sim.dataset import SimulatedDataset, simulate_dataset
from suds_exp.store import Store

if TYPE_CHECKING:
    from suds_exp.ingest import IngestResult


@dataclass
class Simulated:
    """A simulated dataset, what ingest did with each of its files (empty when nothing
    was ingested) and the wall time of the simulation (s)."""

    dataset: SimulatedDataset
    ingested: list[IngestResult] = field(default_factory=list)
    wall_seconds: float = 0.0

    @property
    def n_new(self) -> int:
        """Trials stored by this call (the others were stored already)."""
        return sum(r.status == "ingested" for r in self.ingested)


def check_cycles(cycles: tuple[int, int], text: str | None = None) -> tuple[int, int]:
    """``cycles`` (MIN, MAX) if 1 <= MIN <= MAX, else a `ConfigError` (quoting ``text``,
    the string it was read from, when there is one)."""
    lo, hi = cycles
    if not 1 <= lo <= hi:
        shown = repr(text) if text is not None else f"({lo}, {hi})"
        raise ConfigError(f"cycles {shown}: expected 1 <= MIN <= MAX", param="cycles")
    return int(lo), int(hi)


def simulate_and_ingest(
    store: Store | None,
    out: str | Path,
    config: SimConfig | None = None,
    gaits: Sequence[str] = GAITS,
    frequencies_hz: Sequence[float] = FREQUENCIES_HZ,
    repeats: int = 4,
    cycles: tuple[int, int] = (10, 30),
    seed: int = 0,
    changes: Sequence = (),
    progress: bool = False,
) -> Simulated:
    """Simulate a gait x frequency x repeat design into folder ``out`` and ingest it.

    The arguments are `suds_exp.sim.simulate_dataset`'s (``cycles``: (MIN, MAX) cycles per
    trial; ``changes``: effects switched on during each trial); ``store`` None only
    simulates. Ingest reads the written QTM files and their manifest, so the data takes
    the path a real capture's does. Gaits outside `GAITS` and cycles other than
    1 <= MIN <= MAX are a `ConfigError` (nothing written).
    """
    bad = [g for g in gaits if g not in GAITS]
    if bad or not gaits:
        raise ConfigError(
            f"gaits {list(gaits)!r}: expected some of {', '.join(GAITS)}", param="gaits"
        )
    cycles = check_cycles(tuple(cycles))
    start = time.perf_counter()
    ds = simulate_dataset(
        out,
        config or SimConfig(),
        gaits=tuple(gaits),
        frequencies_hz=tuple(float(f) for f in frequencies_hz),
        repeats=repeats,
        cycles=tuple(cycles),
        seed=seed,
        progress=progress,
        changes=list(changes),
    )
    run = Simulated(ds, wall_seconds=time.perf_counter() - start)
    if store is not None:
        from suds_exp.ingest import ingest_paths  # `simulate` without a store never needs it

        run.ingested = ingest_paths(store, [], manifest=ds.manifest, progress=progress)
    return run
