"""SQLAlchemy Core declarations of the tables the store and ingest own.

The schema itself is created by the SQL files in ``migrations/``; these declarations
mirror it so queries are built with parameters instead of string formatting. They are
never reflected from the database.
"""

import sqlalchemy as sa

from suds_exp.store.declare import declare_table

metadata = sa.MetaData()

trials = declare_table(
    "trials",
    metadata,
    """
    id                        Integer   key
    source_file               String    required
    content_hash              String    required unique
    format                    String    required
    gait                      String
    frequency_hz              Float
    repeat                    Integer
    sample_rate_hz            Float     required
    n_frames                  Integer   required
    marker_names              String[]  required
    layout                    String
    ingested_at               DateTime  required
    notes                     String
    """,
)

markers = declare_table(
    "markers",
    metadata,
    """
    trial_id                  Integer   required
    frame                     Integer   required
    t                         Float     required
    marker                    String    required
    x                         Float
    y                         Float
    z                         Float
    missing                   Boolean   required
    """,
)
