"""SQLAlchemy Core declarations of the discrepancy tables (created by migration 005)."""

import sqlalchemy as sa

metadata = sa.MetaData()

discrepancy_runs = sa.Table(
    "discrepancy_runs",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True),
    sa.Column("name", sa.String, nullable=False),
    sa.Column("prep_version", sa.String),
    sa.Column("start_model", sa.String, nullable=False),
    sa.Column("final_model", sa.String),
    sa.Column("options", sa.String, nullable=False),
    sa.Column("train_trials", sa.String, nullable=False),
    sa.Column("test_trials", sa.String, nullable=False),
    sa.Column("named_effects", sa.String),
    sa.Column("outcome", sa.String),
    sa.Column("report_dir", sa.String),
    sa.Column("seconds", sa.Float),
    sa.Column("started_at", sa.DateTime, nullable=False),
    sa.Column("finished_at", sa.DateTime),
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
