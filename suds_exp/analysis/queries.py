"""Reading labelled results out of the store."""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd

from suds_exp.campaign.grid import KEY_COLUMNS
from suds_exp.errors import AnalysisError
from suds_exp.store import Store

#: Columns of ``results_labelled`` the analyses read (the JSON provenance columns are left
#: in the database: a 100k-row campaign reads in a fraction of the time without them).
ANALYSIS_COLUMNS = KEY_COLUMNS + (
    "rmse_vx",
    "rmse_vy",
    "rmse_wz",
    "gait_steps",
    "gait_sim",
    "period_rel",
    "freq_sim",
    "suds",
    "gmr",
    "phase_only",
    "ln_rmse_vx",
)


def campaigns(store: Store) -> pd.DataFrame:
    """Campaigns with results: ``campaign``, ``n_results``, ``models``, ``n_cycles`` (lists)."""
    return store.query_df(
        "SELECT campaign, count(*) AS n_results, list(DISTINCT model ORDER BY model) AS models, "
        "list(DISTINCT n_cycles ORDER BY n_cycles) AS n_cycles "
        "FROM results GROUP BY campaign ORDER BY campaign"
    )


def load_results(store: Store, campaign: str, columns=ANALYSIS_COLUMNS) -> pd.DataFrame:
    """Rows of the view ``results_labelled`` for one campaign, with a finite RMS error of vx.

    Parameters
    ----------
    store : Store
    campaign : str
        Campaign name as in ``results.campaign``.
    columns : sequence of str, optional
        Columns to read; ``None`` reads all of them.

    Returns
    -------
    DataFrame, one row per result: the ``results`` columns plus ``gait_steps`` (int),
    ``gait_sim`` (same / near / far), ``period_rel`` (<, =, >: model-period against
    data-period), ``freq_sim`` (same / different), ``suds``, ``gmr``, ``phase_only`` (bool)
    and ``ln_rmse_vx`` (natural log of mm/s). Rows whose ``rmse_vx`` is missing, zero or
    infinite (a failed job) are left out.
    """
    select = "*" if columns is None else ", ".join(f'"{c}"' for c in columns)
    query = (
        f"SELECT {select} FROM results_labelled WHERE campaign = ? "
        "AND isfinite(ln_rmse_vx) ORDER BY model, train_gait, train_frequency_hz, "
        "test_gait, test_frequency_hz, n_cycles, boot"
    )
    with store.read() as conn:
        frame = _frame_in_batches(conn.connection.driver_connection, query, [campaign])
    if frame.empty:
        known = campaigns(store)["campaign"].tolist()
        raise AnalysisError(
            f"campaign {campaign!r} has no results with a finite rmse_vx; campaigns with "
            f"results: {', '.join(known) if known else 'none (run a campaign first)'}",
            step=None if known else "run",
        )
    for col in ("gait_sim", "period_rel", "freq_sim"):
        if col in frame:
            frame[col] = frame[col].astype("string")
    return frame


#: Rows fetched from DuckDB at a time by `load_results`.
BATCH_ROWS = 500_000
#: DuckDB's working memory while `load_results` sorts a campaign's rows: beyond it the sort
#: spills to temporary files (beside the database), so DuckDB's share of the peak does not
#: grow with the campaign (5M results: 1.49 GB peak instead of 1.76 GB, measured).
SORT_MEMORY_BYTES = 512 * 2**20


def _frame_in_batches(raw, query: str, params: list) -> pd.DataFrame:
    """The result of ``query`` as one DataFrame: fetched as Arrow batches into one Arrow
    table, which pandas takes over column by column, freeing each as it goes
    (``self_destruct``). The same frame as converting at once, at a fraction of the peak:
    `load_results` of 5M results peaks at 1.6 GB, against 2.7 GB for pandas batches
    concatenated and 4.4 GB for one conversion (measured)."""
    import pyarrow as pa

    spill = _can_spill(raw)
    if spill:
        raw.execute(f"SET memory_limit = '{SORT_MEMORY_BYTES}B'")
    try:
        reader = raw.execute(query, params).to_arrow_reader(BATCH_ROWS)
        table = pa.Table.from_batches(list(reader), schema=reader.schema)
    finally:
        if spill:
            raw.execute("RESET memory_limit")
    return table.to_pandas(split_blocks=True, self_destruct=True)


def _can_spill(raw) -> bool:
    """Whether DuckDB may write its temporary files: a failed attempt breaks every later
    query of the database in this process, so the memory limit is lowered only then. The
    project never sets DuckDB's memory limit, so RESET gives back the default (a setting
    read back as text, '18.8 GiB', is rounded)."""
    (folder,) = raw.execute("SELECT current_setting('temp_directory')").fetchone()
    if not folder:
        return False
    folder = Path(folder)
    return os.access(folder if folder.exists() else folder.parent, os.W_OK)
