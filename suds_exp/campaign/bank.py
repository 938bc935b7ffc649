"""The samples a campaign draws from, decimated once and packed for sharing with workers.

`SampleBank.build` takes a samples frame (columns of the `samples` table plus `gait`
and `frequency_hz`), keeps the trials of the campaign's conditions and:

- decimates each trial to the same number of samples per cycle: the target is the
  smallest samples-per-cycle among those trials (sample rate / gait frequency, e.g.
  100 at 1 Hz and 100 Hz capture) and a trial keeps every k-th sample, k =
  round(its samples per cycle / target), counted from its first sample. Plain
  decimation, no filter, so every condition keeps the same measurement noise;
- finds each trial's complete cycles: a `cycle` value whose samples span at least
  2 pi minus 2.5 median phase steps of the raw trial (the partial first and last
  cycles of a recording fall out), grouped in runs of consecutive cycle numbers.

All numeric columns are packed in one float64 array of shape (n_rows, n_columns) in
(trial, time) order, so a worker gets the whole bank as one memory map (loky) or one
scattered object (dask) instead of a copy per job.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.campaign.conditions import Condition, condition_sort_key, format_condition, round_hz
from suds_exp.errors import CampaignError
from suds_exp.robot import SAMPLE_KEYS, VB_COLUMNS

_RP = re.compile(r"^d?rp_\d+$")
_RA_MORE = re.compile(r"^d?ra_\d+$")
_TWO_PI = 2.0 * np.pi
#: A cycle is complete when its samples span 2 pi less at most this many phase steps.
COMPLETE_SLACK_STEPS = 2.5


def sample_columns(samples: pd.DataFrame) -> list[str]:
    """The standard numeric sample columns present in ``samples``, in contract order."""
    missing = [c for c in (*SAMPLE_KEYS, *VB_COLUMNS) if c not in samples.columns]
    if missing:
        raise CampaignError(
            f"samples frame lacks column(s) {', '.join(missing)}; expected the columns of "
            "the `samples` table (suds_exp.robot.sample_columns)"
        )
    rp = sorted((c for c in samples.columns if _RP.match(str(c))), key=lambda c: (c[0] == "d", c))
    # r_a beyond the two joint angles (the paper preset's Cartesian values)
    ra = [c for c in samples.columns if _RA_MORE.match(str(c)) and c not in SAMPLE_KEYS]
    ra.sort(key=lambda c: (c[0] == "d", int(c.rsplit("_", 1)[1])))
    return [*SAMPLE_KEYS, *ra, *rp, *VB_COLUMNS]


@dataclass(frozen=True)
class SampleBank:
    """Decimated samples of a campaign's trials, as arrays a worker can share.

    Attributes
    ----------
    values : array of shape (n_rows, len(columns)), float64
        Every numeric sample column, rows in (trial, t) order; units as in `samples`.
    columns : tuple of str
        Column names of ``values``.
    trial_ids : array of shape (n_trials,), int
    row_start, row_stop : arrays of shape (n_trials,), int
        Rows of each trial in ``values``.
    trial_condition : tuple of Condition
        (gait, frequency_hz) of each trial.
    runs : tuple of tuple of (first_cycle, last_cycle)
        Complete consecutive cycles of each trial.
    samples_per_cycle : int
        Target samples per cycle after decimation.
    decimation : dict of frequency_hz -> int
        Decimation factor used at each frequency.
    """

    values: np.ndarray
    columns: tuple[str, ...]
    trial_ids: np.ndarray
    row_start: np.ndarray
    row_stop: np.ndarray
    trial_condition: tuple[Condition, ...]
    runs: tuple[tuple[tuple[int, int], ...], ...]
    samples_per_cycle: int
    decimation: dict[float, int] = field(default_factory=dict)

    # -- construction --------------------------------------------------------------
    @classmethod
    def build(cls, samples: pd.DataFrame, conditions: list[Condition] | None = None) -> SampleBank:
        """Decimate and pack the trials of ``conditions`` (all conditions when None)."""
        if "gait" not in samples.columns or "frequency_hz" not in samples.columns:
            raise CampaignError(
                "samples frame lacks `gait`/`frequency_hz`; load it with load_samples"
            )
        columns = sample_columns(samples)
        frame = samples.loc[samples["gait"].notna() & samples["frequency_hz"].notna()]
        hz = frame["frequency_hz"].astype(float).round(6)
        if conditions is not None:
            wanted = pd.MultiIndex.from_tuples(conditions)
            keep = pd.MultiIndex.from_arrays([frame["gait"], hz]).isin(wanted)
            frame, hz = frame.loc[keep], hz.loc[keep]
        if frame.empty:
            raise CampaignError("no samples with a (gait, frequency) condition to run on")
        order = np.lexsort((frame["t"].to_numpy(float), frame["trial_id"].to_numpy()))
        values = frame[columns].to_numpy(dtype=np.float64)[order]
        gait = frame["gait"].astype(str).to_numpy()[order]
        hz = hz.to_numpy()[order]
        trial = values[:, 0].astype(np.int64)
        edges = np.flatnonzero(np.diff(trial)) + 1
        lo = np.concatenate([[0], edges])
        hi = np.concatenate([edges, [len(trial)]])
        t_col, ph_col, cy_col = (columns.index(c) for c in ("t", "phase", "cycle"))

        raw_spc = []
        for a, b in zip(lo, hi, strict=True):
            if (gait[a:b] != gait[a]).any() or (hz[a:b] != hz[a]).any():
                raise CampaignError(f"samples of trial {trial[a]} have more than one condition")
            dt = np.median(np.diff(values[a:b, t_col])) if b - a > 1 else np.nan
            if not np.isfinite(dt) or dt <= 0:
                raise CampaignError(f"trial {trial[a]}: cannot tell its sample rate from column t")
            raw_spc.append(1.0 / (dt * hz[a]))
        target = int(round(min(raw_spc)))

        keep = np.zeros(len(trial), dtype=bool)
        starts, stops, conds_out, runs_out = [], [], [], []
        decimation: dict[float, int] = {}
        row = 0
        for a, b, spc in zip(lo, hi, raw_spc, strict=True):
            cond = (str(gait[a]), float(hz[a]))
            k = max(1, int(round(spc / target)))
            decimation.setdefault(cond[1], k)
            runs_out.append(_complete_runs(values[a:b, ph_col], values[a:b, cy_col]))
            keep[a:b:k] = True
            starts.append(row)
            row += len(range(a, b, k))
            stops.append(row)
            conds_out.append(cond)
        tids = trial[lo]
        return cls(
            values=np.ascontiguousarray(values[keep]),
            columns=tuple(columns),
            trial_ids=np.asarray(tids, dtype=np.int64),
            row_start=np.asarray(starts, dtype=np.int64),
            row_stop=np.asarray(stops, dtype=np.int64),
            trial_condition=tuple(conds_out),
            runs=tuple(runs_out),
            samples_per_cycle=target,
            decimation=dict(sorted(decimation.items())),
        )

    def memmapped(self, folder: str | Path) -> SampleBank:
        """The same bank with ``values`` in a read-only memory-mapped .npy file in
        ``folder`` (the caller removes it).

        joblib's loky backend pickles a file-backed memory map as its file name, so every
        worker maps the same pages instead of receiving a copy per task.
        """
        path = Path(folder) / "bank_values.npy"
        np.save(path, self.values)
        return replace(self, values=np.load(path, mmap_mode="r"))

    # -- look-ups --------------------------------------------------------------------
    @property
    def conditions(self) -> list[Condition]:
        return sorted(set(self.trial_condition), key=condition_sort_key)

    def trials_of(self, cond: Condition) -> list[int]:
        """Indices (into ``trial_ids``) of the trials of ``cond`` that have complete cycles."""
        return [i for i, c in enumerate(self.trial_condition) if c == cond and self.runs[i]]

    def n_cycles(self, i: int) -> int:
        """Complete cycles of trial index ``i``."""
        return sum(b - a + 1 for a, b in self.runs[i])

    def rows(self, i: int, first: int, last: int) -> np.ndarray:
        """``values`` rows of trial index ``i`` whose cycle is in [first, last], shape
        (n_rows, len(columns)); a read-only view where the trial's cycles ascend."""
        block = np.asarray(self.values[self.row_start[i] : self.row_stop[i]])
        cycle = block[:, self._layout.cycle]
        if len(cycle) > 1 and not (cycle[1:] >= cycle[:-1]).all():
            return block[(cycle >= first) & (cycle <= last)]
        # time-ordered cycles: the rows in [first, last] are one contiguous run
        lo = np.searchsorted(cycle, first, side="left")
        hi = np.searchsorted(cycle, last, side="right")
        return block[lo:hi]

    def frame(self, pieces: list[np.ndarray]) -> pd.DataFrame:
        """A samples frame (float columns; trial_id, frame, cycle as int) of row blocks
        (each of shape (n_rows, len(columns))), in the order given."""
        data = np.concatenate(pieces) if len(pieces) > 1 else np.array(pieces[0])
        return self._layout.frame(data)

    @cached_property
    def _layout(self) -> _FrameLayout:
        return _FrameLayout(self.columns)

    def describe(self) -> dict[str, list[int]]:
        """Condition -> ids of the trials used, for the campaign definition."""
        out: dict[str, list[int]] = {}
        for cond in self.conditions:
            out[format_condition(cond)] = [int(self.trial_ids[i]) for i in self.trials_of(cond)]
        return out


class _FrameLayout:
    """How a bank's columns become a samples frame: two blocks (the float columns, and
    trial_id, frame, cycle as int64) handed to pandas as they are.

    The same frame as one column per array, built in a third of the time, and a shallow
    copy of it (one per learner) costs two blocks' bookkeeping instead of one per column.
    Needs `pandas.api.internals` (pandas >= 2.3); older pandas builds it column by column.
    """

    INT_COLUMNS = ("trial_id", "frame", "cycle")

    def __init__(self, columns: tuple[str, ...]):
        self.columns = pd.Index(columns)
        self.cycle = columns.index("cycle")
        self.ints = np.array([columns.index(c) for c in self.INT_COLUMNS])
        self.floats = np.array([j for j in range(len(columns)) if j not in set(self.ints)])
        self.names = columns

    def frame(self, data: np.ndarray) -> pd.DataFrame:
        """The frame of ``data``, shape (n_rows, n_columns), float64."""
        try:
            from pandas.api.internals import create_dataframe_from_blocks
        except ImportError:  # pandas < 2.3
            columns = {c: data[:, j] for j, c in enumerate(self.names)}
            for c in self.INT_COLUMNS:
                columns[c] = columns[c].astype(np.int64)
            return pd.DataFrame(columns, copy=False)
        by_column = data.T  # pandas keeps a block as (columns, rows)
        blocks = [
            (by_column[self.floats], self.floats),
            (by_column[self.ints].astype(np.int64), self.ints),
        ]
        return create_dataframe_from_blocks(
            blocks, index=pd.RangeIndex(len(data)), columns=self.columns
        )


def _complete_runs(phase: np.ndarray, cycle: np.ndarray) -> tuple[tuple[int, int], ...]:
    """Runs (first, last) of consecutive complete cycles of one trial's raw samples."""
    if len(phase) < 3:
        return ()
    step = float(np.median(np.abs(np.diff(phase))))
    cycle = cycle.astype(np.int64)
    ids, inverse = np.unique(cycle, return_inverse=True)
    lo = np.full(len(ids), np.inf)
    hi = np.full(len(ids), -np.inf)
    np.minimum.at(lo, inverse, phase)
    np.maximum.at(hi, inverse, phase)
    complete = ids[(hi - lo) >= _TWO_PI - COMPLETE_SLACK_STEPS * step]
    runs: list[tuple[int, int]] = []
    for c in complete.tolist():
        if runs and c == runs[-1][1] + 1:
            runs[-1] = (runs[-1][0], c)
        else:
            runs.append((c, c))
    return tuple(runs)


def rounded_conditions(samples: pd.DataFrame) -> list[Condition]:
    """The (gait, frequency_hz rounded to 6 decimals) conditions present in ``samples``."""
    known = samples["gait"].notna() & samples["frequency_hz"].notna()
    have = samples.loc[known, ["gait", "frequency_hz"]]
    pairs = {(str(g), round_hz(f)) for g, f in have.drop_duplicates().itertuples(index=False)}
    return sorted(pairs, key=condition_sort_key)
