"""SQLAlchemy Core declarations of the preprocessing tables (schema: migration 002)."""

import sqlalchemy as sa

from suds_exp.robot import DRP_COLUMNS, RP_COLUMNS

metadata = sa.MetaData()

prep_versions = sa.Table(
    "prep_versions",
    metadata,
    sa.Column("id", sa.Integer, primary_key=True),
    sa.Column("name", sa.String, nullable=False, unique=True),
    sa.Column("params_hash", sa.String, nullable=False, unique=True),
    sa.Column("params", sa.String, nullable=False),
    sa.Column("k", sa.Integer, nullable=False),
    sa.Column("created_at", sa.DateTime, nullable=False),
)

prep_fits = sa.Table(
    "prep_fits",
    metadata,
    sa.Column("version_id", sa.Integer, primary_key=True),
    sa.Column("kind", sa.String, primary_key=True),
    sa.Column("grp", sa.String, primary_key=True),
    sa.Column("state", sa.String, nullable=False),
    sa.Column("trial_ids", sa.ARRAY(sa.Integer), nullable=False),
    sa.Column("n_frames", sa.Integer, nullable=False),
    sa.Column("fitted_at", sa.DateTime, nullable=False),
)

prep_pca = sa.Table(
    "prep_pca",
    metadata,
    sa.Column("version_id", sa.Integer, nullable=False),
    sa.Column("component", sa.Integer, nullable=False),
    sa.Column("explained_variance", sa.Float, nullable=False),
    sa.Column("explained_variance_ratio", sa.Float, nullable=False),
    sa.Column("cumulative_ratio", sa.Float, nullable=False),
    sa.Column("kept", sa.Boolean, nullable=False),
    sa.Column("loadings", sa.ARRAY(sa.Float), nullable=False),
)

prep_trials = sa.Table(
    "prep_trials",
    metadata,
    sa.Column("version_id", sa.Integer, nullable=False),
    sa.Column("trial_id", sa.Integer, nullable=False),
    sa.Column("n_frames", sa.Integer, nullable=False),
    sa.Column("n_jumps", sa.Integer, nullable=False),
    sa.Column("removed_fraction", sa.Float, nullable=False),
    sa.Column("filled_fraction", sa.Float, nullable=False),
    sa.Column("longest_gap_frames", sa.Integer, nullable=False),
    sa.Column("plane_normal", sa.ARRAY(sa.Float), nullable=False),
    sa.Column("middle_length_mm", sa.Float, nullable=False),
    sa.Column("joint_rms_mm", sa.Float, nullable=False),
    sa.Column("phaser_group", sa.String, nullable=False),
    sa.Column("done_at", sa.DateTime, nullable=False),
)


samples = sa.Table(
    "samples",
    metadata,
    sa.Column("version_id", sa.Integer, nullable=False),
    sa.Column("trial_id", sa.Integer, nullable=False),
    sa.Column("frame", sa.Integer, nullable=False),
    sa.Column("t", sa.Float, nullable=False),
    sa.Column("phase", sa.Float, nullable=False),
    sa.Column("cycle", sa.Integer, nullable=False),
    sa.Column("ra_1", sa.Float, nullable=False),
    sa.Column("ra_2", sa.Float),
    sa.Column("dra_1", sa.Float, nullable=False),
    sa.Column("dra_2", sa.Float),
    *(sa.Column(c, sa.Float) for c in RP_COLUMNS),
    *(sa.Column(c, sa.Float) for c in DRP_COLUMNS),
    sa.Column("vx", sa.Float, nullable=False),
    sa.Column("vy", sa.Float, nullable=False),
    sa.Column("wz", sa.Float, nullable=False),
    # migration 011: the Cartesian r_a's last two values (NULL for joint angles)
    *(sa.Column(c, sa.Float) for c in ("ra_3", "ra_4", "dra_3", "dra_4")),
    # migration 018: up to 8 actuated joints of a segment body (ra_2, dra_2 may be NULL)
    *(sa.Column(f"{p}_{i}", sa.Float) for i in range(5, 9) for p in ("ra", "dra")),
)
