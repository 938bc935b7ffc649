"""SQLAlchemy Core declarations of the campaign tables (created by migration 003)."""

import sqlalchemy as sa

from suds_exp.campaign.grid import KEY_COLUMNS

metadata = sa.MetaData()

campaigns = sa.Table(
    "campaigns",
    metadata,
    sa.Column("name", sa.String, primary_key=True),
    sa.Column("prep_version", sa.String, nullable=False),
    sa.Column("definition", sa.String, nullable=False),
    sa.Column("n_jobs", sa.Integer, nullable=False),
    sa.Column("created_at", sa.DateTime, nullable=False),
)

campaign_runs = sa.Table(
    "campaign_runs",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True),
    sa.Column("campaign", sa.String, nullable=False),
    sa.Column("started_at", sa.DateTime, nullable=False),
    sa.Column("pid", sa.Integer, nullable=False),
    sa.Column("host", sa.String, nullable=False),
    sa.Column("backend", sa.String, nullable=False),
    sa.Column("n_workers", sa.Integer, nullable=False),
    sa.Column("n_pending", sa.Integer, nullable=False),
)

results = sa.Table(
    "results",
    metadata,
    sa.Column("campaign", sa.String, nullable=False),
    sa.Column("model", sa.String, nullable=False),
    sa.Column("train_gait", sa.String, nullable=False),
    sa.Column("train_frequency_hz", sa.Float, nullable=False),
    sa.Column("test_gait", sa.String, nullable=False),
    sa.Column("test_frequency_hz", sa.Float, nullable=False),
    sa.Column("boot", sa.Integer, nullable=False),
    sa.Column("n_cycles", sa.Integer, nullable=False),
    sa.Column("train_trials", sa.String, nullable=False),
    sa.Column("train_ranges", sa.String, nullable=False),
    sa.Column("test_trial", sa.Integer, nullable=False),
    sa.Column("test_range", sa.String, nullable=False),
    sa.Column("rmse_vx", sa.Float),
    sa.Column("rmse_vy", sa.Float),
    sa.Column("rmse_wz", sa.Float),
    sa.Column("n_test", sa.Integer, nullable=False),
    sa.Column("fit_seconds", sa.Float, nullable=False),
    sa.Column("predict_seconds", sa.Float, nullable=False),
    sa.Column("finished_at", sa.DateTime, nullable=False),
    sa.Column("error", sa.String),
    sa.UniqueConstraint(*KEY_COLUMNS),
)
