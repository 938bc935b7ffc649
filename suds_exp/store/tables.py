"""SQLAlchemy Core declarations of the tables the store and ingest own.

The schema itself is created by the SQL files in ``migrations/``; these declarations
mirror it so queries are built with parameters instead of string formatting. They are
never reflected from the database.
"""

import sqlalchemy as sa

metadata = sa.MetaData()

trials = sa.Table(
    "trials",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True),
    sa.Column("source_file", sa.String, nullable=False),
    sa.Column("content_hash", sa.String, nullable=False, unique=True),
    sa.Column("format", sa.String, nullable=False),
    sa.Column("gait", sa.String),
    sa.Column("frequency_hz", sa.Float),
    sa.Column("repeat", sa.Integer),
    sa.Column("sample_rate_hz", sa.Float, nullable=False),
    sa.Column("n_frames", sa.Integer, nullable=False),
    sa.Column("marker_names", sa.ARRAY(sa.String), nullable=False),
    sa.Column("layout", sa.String),
    sa.Column("ingested_at", sa.DateTime, nullable=False),
    sa.Column("notes", sa.String),
)

markers = sa.Table(
    "markers",
    metadata,
    sa.Column("trial_id", sa.Integer, nullable=False),
    sa.Column("frame", sa.Integer, nullable=False),
    sa.Column("t", sa.Float, nullable=False),
    sa.Column("marker", sa.String, nullable=False),
    sa.Column("x", sa.Float),
    sa.Column("y", sa.Float),
    sa.Column("z", sa.Float),
    sa.Column("missing", sa.Boolean, nullable=False),
)
