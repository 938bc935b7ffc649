"""Simulate a design and ingest its files, as a capture system's would be.

This is the one place that chains `suds_exp.sim` and `suds_exp.ingest`, which stay
independent of each other (an import-linter contract).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from suds_exp.sim.config import SimConfig
from suds_exp.sim.dataset import SimDesign, SimulatedDataset, simulate_dataset
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


def simulate_and_ingest(
    store: Store | None,
    out: str | Path,
    config: SimConfig | None = None,
    design: SimDesign | None = None,
    progress: bool = False,
) -> Simulated:
    """Simulate ``design`` (default: the paper's) on the robot of ``config`` into folder
    ``out`` and ingest it; ``store`` None only simulates.

    Ingest reads the written QTM files and their manifest, so the data takes the path a
    real capture's does.
    """
    start = time.perf_counter()
    ds = simulate_dataset(
        out, config or SimConfig(), progress=progress, **(design or SimDesign()).keywords()
    )
    run = Simulated(ds, wall_seconds=time.perf_counter() - start)
    if store is not None:
        from suds_exp.ingest import ingest_paths  # `simulate` without a store never needs it

        run.ingested = ingest_paths(store, [], manifest=ds.manifest, progress=progress)
    return run
