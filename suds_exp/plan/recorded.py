"""The gaits a version's trials ran, as the planner knows them: the paper's gaits by
name and each gait file found by its name (a trial's gait label is its file's name).

A gait file is looked for where the planner writes it (a loop's folder, `plan next`'s
``out``, searched below) and beside each trial's capture file (where a loop records it,
and where a user keeps it). A label found nowhere is not counted as a recorded gait and
is named in ``missing``, so that the gait goal's "best recorded gait" is never silently
the best of a subset."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from suds_exp.gait.shape import Gait, NamedGait, read_gait_file
from suds_exp.ingest.manifest import GAIT_FILE_SUFFIXES
from suds_exp.preprocess.pipeline import trial_meta
from suds_exp.robot import GAITS
from suds_exp.store import Store


@dataclass
class RecordedGaits:
    """labels: the recorded gait labels the planner knows, sorted; gaits: their gaits
    (at least the paper's O when none is known); missing: the labels of gait files found
    nowhere."""

    labels: list[str]
    gaits: list[Gait]
    missing: list[str] = field(default_factory=list)


def capture_folders(store: Store, trial_ids) -> list[Path]:
    """The folders of the capture files of trials ``trial_ids`` (distinct, sorted)."""
    with store.read() as conn:
        files = trial_meta(conn, trial_ids, ("id", "source_file"))["source_file"]
    return sorted({Path(f).parent for f in files.dropna().astype(str)})


def recorded_gaits(
    samples: pd.DataFrame, folder: Path, store: Store | None = None
) -> RecordedGaits:
    """The gaits the trials of ``samples`` ran (see the module docstring): gait files
    under ``folder`` (any depth) or, with ``store``, beside the trials' capture files."""
    found = {
        p.name: p for suffix in GAIT_FILE_SUFFIXES for p in Path(folder).glob(f"**/*{suffix}")
    }
    beside = capture_folders(store, samples["trial_id"].unique()) if store is not None else []
    labels, gaits, missing = [], [], []
    for label in sorted(set(samples["gait"].dropna().astype(str))):
        if label in GAITS:
            gaits.append(NamedGait(label))
        else:
            path = found.get(label) or next(
                (f / label for f in beside if (f / label).is_file()), None
            )
            if path is None:
                missing.append(label)
                continue
            gaits.append(read_gait_file(path))
        labels.append(label)
    if not gaits:
        return RecordedGaits(["O"], [NamedGait("O")], missing)
    return RecordedGaits(labels, gaits, missing)
