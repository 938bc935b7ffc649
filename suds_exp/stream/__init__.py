"""Prequential evaluation of learners on a changing robot (`suds-exp stream`).

- `run_stream(store, name, models, trials, ...)`: predict each cycle, score it, then learn
  it; one row per cycle in `stream_cycles`, resumable.
- `summarise(rows)`, `trial_outcomes(rows)`, `plot_error(rows, path)`: recovery time to
  x1.25 of the pre-change error, Page-Hinkley alarm delay and false-alarm rate.
- `run_trial(trial, model, params, settings)`: the same for one trial, without a database.
- `simulate_stream_samples(...)`: simulated samples straight from truth, with scheduled
  changes (`suds_exp.sim.schedule`).
"""

from suds_exp.stream.drift import PageHinkley
from suds_exp.stream.prequential import CYCLE_COLUMNS, TIMING_COLUMNS, StreamSettings, run_trial
from suds_exp.stream.report import plot_error, summarise, trial_outcomes
from suds_exp.stream.runner import StreamError, StreamSummary, run_stream, stream_rows
from suds_exp.stream.simulated import samples_from_truth, simulate_stream_samples

__all__ = [
    "CYCLE_COLUMNS",
    "TIMING_COLUMNS",
    "PageHinkley",
    "StreamError",
    "StreamSettings",
    "StreamSummary",
    "plot_error",
    "run_stream",
    "run_trial",
    "samples_from_truth",
    "simulate_stream_samples",
    "stream_rows",
    "summarise",
    "trial_outcomes",
]
