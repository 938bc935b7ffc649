"""Record a planned trial on the simulator standing in for the robot: simulate it (the
simulator's own actuator and measurement noise, cycle to cycle, drawn from the trial's
seed), ingest its capture and preprocess it into the version.

`add_trial_to_version` is the one place a plan's trial joins the stored data. Its capture
is ingested by the ordinary manifest path (a declared level with the paper's condition, a
gait file with the file's name as its gait), and a gait file's trial becomes an added
level of the stored experiment design (`suds_exp.ingest.add_trial_levels`, as `gait
design --verify`'s), so `run`, `report` and `findings` take it as a condition; a trial
recorded twice (a loop resumed after a kill) is the same file, which ingest skips as
already stored, preprocessing as already done and the design as already added.
"""

from __future__ import annotations

from pathlib import Path

import sqlalchemy as sa

from suds_exp.gait.shape import FourierGait
from suds_exp.gait.trials import simulate_gait_file
from suds_exp.ingest import add_trial_levels, ingest_paths
from suds_exp.ingest.added import mark_trials_added
from suds_exp.plan.recommend import Trial
from suds_exp.preprocess import preprocess as run_preprocess
from suds_exp.robot import GAITS
from suds_exp.sim import SimConfig, simulate_dataset
from suds_exp.sim.dataset import draw_trial, trial_seed
from suds_exp.store import Store


def next_repeat(store: Store, gait: str, frequency_hz: float, taken_by: str | None = None) -> int:
    """The next free repeat number of condition (gait, frequency_hz) in ``store``."""
    if not store.path.exists():
        return 1
    with store.read() as conn:
        top = conn.execute(
            sa.text(
                "SELECT max(repeat) FROM trials WHERE gait = :g AND round(frequency_hz, 6) = :f"
            ),
            {"g": gait, "f": round(float(frequency_hz), 6)},
        ).scalar()
    return int(top or 0) + 1


def is_declared(trial: Trial) -> bool:
    """True for a trial of a declared level (a paper gait, no gait file)."""
    return trial.file is None and trial.gait.name in GAITS


def record_trial(
    store: Store, trial: Trial, folder: Path, seed: int, config: SimConfig | None = None
) -> int:
    """Simulate ``trial`` into ``folder`` and ingest it; its trial id.

    A declared level (a paper gait) takes the condition's next free repeat; a gait file's
    trial is repeat 1 of its own gait (the file's name). ``seed``: the trial's seed."""
    folder.mkdir(parents=True, exist_ok=True)
    cycles = (int(trial.cycles), int(trial.cycles))
    if is_declared(trial):
        marker = folder / "repeat.txt"
        # the repeat is chosen once and kept, so a resumed recording writes the same file
        if marker.is_file():
            repeat = int(marker.read_text())
        else:
            repeat = next_repeat(store, trial.gait.name, trial.frequency_hz)
            marker.write_text(str(repeat))
        spec = draw_trial(
            trial.gait.name,
            trial.frequency_hz,
            repeat,
            trial_seed(seed, trial.gait.name, trial.frequency_hz, repeat),
            cycles,
        )
        ds = simulate_dataset(folder, config or SimConfig(), specs=[spec])
        results = ingest_paths(store, [], manifest=ds.manifest, progress=False)
        return int(results[0].trial_id)
    gait = trial.gait
    if isinstance(gait, FourierGait) and trial.file is not None:
        (folder / Path(trial.file).name).write_text(gait.to_toml())
    summary = simulate_gait_file(
        folder, gait, config, (trial.frequency_hz,), 1, cycles, seed, store
    )
    return int(summary["trial_ids"][0])


def add_trial_to_version(
    store: Store,
    version,
    trial: Trial,
    folder: Path,
    seed: int,
    config: SimConfig | None = None,
    added_by: str = "plan loop",
) -> int:
    """Record ``trial`` (`record_trial`) and preprocess it into ``version`` (a
    `suds_exp.preprocess.Version`) with the version's own parameters; its trial id.

    The one call site where a plan's trials become part of the data, and so of the
    experiment's design: the trial is marked as recorded by ``added_by``
    (`mark_trials_added`), and a gait file's trial (labelled with the file's name) becomes
    an added level of the stored design, recorded as added by ``added_by``."""
    trial_id = record_trial(store, trial, folder, seed, config)
    mark_trials_added(store, [trial_id], added_by)
    if not is_declared(trial):
        add_trial_levels(store, {trial_id: trial.gait.name}, added_by=added_by)
    run_preprocess(store, version.name, params=version.params, trials=[trial_id], progress=False)
    return trial_id
