"""The trials table as users see it."""

from __future__ import annotations

import pandas as pd

from suds_exp.store import Store
from suds_exp.store.rows import trial_rows


def list_trials(store: Store) -> pd.DataFrame:
    """One row per trial: id, file, format, condition, rate (Hz), frames, markers."""
    return trial_rows(store.path).to_frame()
