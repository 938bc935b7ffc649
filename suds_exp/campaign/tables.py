"""SQLAlchemy Core declarations of the campaign tables (created by migration 003)."""

import sqlalchemy as sa

from suds_exp.campaign.grid import KEY_COLUMNS
from suds_exp.store.declare import declare_table

metadata = sa.MetaData()

campaigns = declare_table(
    "campaigns",
    metadata,
    """
    name                      String    key
    prep_version              String    required
    definition                String    required
    n_jobs                    Integer   required
    created_at                DateTime  required
    """,
)

campaign_runs = declare_table(
    "campaign_runs",
    metadata,
    """
    id                        Integer   key
    campaign                  String    required
    started_at                DateTime  required
    pid                       Integer   required
    host                      String    required
    backend                   String    required
    n_workers                 Integer   required
    n_pending                 Integer   required
    """,
)

results = declare_table(
    "results",
    metadata,
    """
    campaign                  String    required
    model                     String    required
    train_gait                String    required
    train_frequency_hz        Float     required
    test_gait                 String    required
    test_frequency_hz         Float     required
    boot                      Integer   required
    n_cycles                  Integer   required
    train_trials              String    required
    train_ranges              String    required
    test_trial                Integer   required
    test_range                String    required
    rmse_vx                   Float
    rmse_vy                   Float
    rmse_wz                   Float
    n_test                    Integer   required
    fit_seconds               Float     required
    predict_seconds           Float     required
    finished_at               DateTime  required
    error                     String
    """,
    sa.UniqueConstraint(*KEY_COLUMNS),
)
