"""The trials table as users see it."""

from __future__ import annotations

import pandas as pd
import sqlalchemy as sa

from suds_exp.store import Store
from suds_exp.store.tables import trials


def list_trials(store: Store) -> pd.DataFrame:
    """One row per trial: id, file, format, condition, rate (Hz), frames, markers."""
    query = sa.select(
        trials.c.id,
        trials.c.source_file,
        trials.c.format,
        trials.c.gait,
        trials.c.frequency_hz,
        trials.c.repeat,
        trials.c.sample_rate_hz,
        trials.c.n_frames,
        sa.func.len(trials.c.marker_names).label("n_markers"),
        trials.c.ingested_at,
        trials.c.notes,
    ).order_by(trials.c.id)
    return store.query_df(query)
