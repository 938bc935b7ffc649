"""SQLAlchemy Core declarations of the discrepancy tables (created by migration 005)."""

import sqlalchemy as sa

from suds_exp.store.declare import declare_table

metadata = sa.MetaData()

discrepancy_runs = declare_table(
    "discrepancy_runs",
    metadata,
    """
    id                        Integer   key
    name                      String    required
    prep_version              String
    start_model               String    required
    final_model               String
    options                   String    required
    train_trials              String    required
    test_trials               String    required
    named_effects             String
    outcome                   String
    report_dir                String
    seconds                   Float
    started_at                DateTime  required
    finished_at               DateTime
    """,
)

STEP_COLUMNS = (
    "run_id",
    "step",
    "model",
    "test_loss",
    "test_rmse_vx",
    "test_rmse_vy",
    "test_rmse_wz",
    "n_candidates",
    "decision",
    "accepted",
    "parameter",
    "value",
    "ci_low",
    "ci_high",
    "unit",
    "p_adjusted",
    "gap_closed",
    "systematic_z",
    "systematic_p",
    "correlations",
)

CANDIDATE_COLUMNS = (
    "run_id",
    "step",
    "candidate",
    "effect",
    "parameter",
    "value",
    "ci_low",
    "ci_high",
    "unit",
    "train_loss_before",
    "train_loss_after",
    "test_loss_before",
    "test_loss_after",
    "improvement",
    "p_value",
    "p_adjusted",
    "significant",
    "accepted",
    "n_replays",
    "seconds",
)
