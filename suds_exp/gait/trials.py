"""Capture sessions of a gait from a file: `suds-exp simulate --gait-file FILE`.

The simulator's trial machinery (`suds_exp.sim.dataset`) drives the gait through the
actuator and the physics and writes the same TSV, truth and manifest files as for the
paper's gaits; the manifest names the file as the gait. Each trial's randomness derives
from (seed, the gait's name, frequency, repeat).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

from suds_exp.gait.predict import derive_seed
from suds_exp.gait.shape import Gait
from suds_exp.sim import SimConfig, simulate_dataset
from suds_exp.sim.dataset import TrialSpec, draw_trial


def gait_trial_specs(
    gait: Gait,
    frequencies_hz: Sequence[float] = (0.5,),
    repeats: int = 1,
    cycles: tuple[int, int] = (10, 10),
    seed: int = 0,
) -> list[TrialSpec]:
    """Trial specs of ``gait`` at each frequency (Hz) x repeat; cycles drawn from
    ``cycles`` (MIN, MAX); start phase, pose and noise from the trial's own seed."""
    code = derive_seed("gait-file", gait.name) % 1_000_000
    specs = []
    for f in frequencies_hz:
        for r in range(1, repeats + 1):
            ent = (int(seed), 100 + code, int(round(f * 1e6)), r)
            specs.append(draw_trial(gait.name, f, r, ent, cycles, path=gait.shape))
    return specs


def simulate_gait_file(
    out: Path,
    gait: Gait,
    config: SimConfig | None = None,
    frequencies_hz: Sequence[float] = (0.5,),
    repeats: int = 1,
    cycles: tuple[int, int] = (10, 10),
    seed: int = 0,
    store=None,
    progress: bool = False,
) -> dict:
    """Simulate trials of ``gait`` into ``out`` and (given a `Store`) ingest them; a
    JSON-ready summary like `suds_exp.commands.simulate.simulate_command`'s."""
    start = time.perf_counter()
    specs = gait_trial_specs(gait, frequencies_hz, repeats, cycles, seed)
    ds = simulate_dataset(out, config or SimConfig(), specs=specs, progress=progress)
    summary = {
        "out": str(out),
        "manifest": str(ds.manifest),
        "files": [str(p) for p in ds.tsv_paths],
        "n_trials": len(ds.tsv_paths),
        "gait": gait.name,
        "simulated_seconds": round(float(ds.simulated_seconds), 3),
        "wall_seconds": round(time.perf_counter() - start, 3),
        "trial_ids": None,
    }
    if store is not None:
        from suds_exp.ingest import ingest_paths

        results = ingest_paths(store, [], manifest=ds.manifest, progress=False)
        summary["trial_ids"] = [r.trial_id for r in results]
    return summary
