"""SQLAlchemy Core declarations of the preprocessing tables (schema: migration 002)."""

import sqlalchemy as sa

from suds_exp.robot import DRP_COLUMNS, RP_COLUMNS
from suds_exp.store.declare import columns, declare_table

metadata = sa.MetaData()

prep_versions = declare_table(
    "prep_versions",
    metadata,
    """
    id                        Integer   key
    name                      String    required unique
    params_hash               String    required unique
    params                    String    required
    k                         Integer   required
    created_at                DateTime  required
    """,
)

prep_fits = declare_table(
    "prep_fits",
    metadata,
    """
    version_id                Integer   key
    kind                      String    key
    grp                       String    key
    state                     String    required
    trial_ids                 Integer[] required
    n_frames                  Integer   required
    fitted_at                 DateTime  required
    """,
)

prep_pca = declare_table(
    "prep_pca",
    metadata,
    """
    version_id                Integer   required
    component                 Integer   required
    explained_variance        Float     required
    explained_variance_ratio  Float     required
    cumulative_ratio          Float     required
    kept                      Boolean   required
    loadings                  Float[]   required
    """,
)

prep_trials = declare_table(
    "prep_trials",
    metadata,
    """
    version_id                Integer   required
    trial_id                  Integer   required
    n_frames                  Integer   required
    n_jumps                   Integer   required
    removed_fraction          Float     required
    filled_fraction           Float     required
    longest_gap_frames        Integer   required
    plane_normal              Float[]   required
    middle_length_mm          Float     required
    joint_rms_mm              Float     required
    phaser_group              String    required
    done_at                   DateTime  required
    """,
)


samples = declare_table(
    "samples",
    metadata,
    """
    version_id                Integer   required
    trial_id                  Integer   required
    frame                     Integer   required
    t                         Float     required
    phase                     Float     required
    cycle                     Integer   required
    ra_1                      Float     required
    ra_2                      Float
    dra_1                     Float     required
    dra_2                     Float
    """,
    *(sa.Column(c, sa.Float) for c in RP_COLUMNS),
    *(sa.Column(c, sa.Float) for c in DRP_COLUMNS),
    *columns("vx Float required\nvy Float required\nwz Float required"),
    # migration 011: the Cartesian r_a's last two values (NULL for joint angles)
    *(sa.Column(c, sa.Float) for c in ("ra_3", "ra_4", "dra_3", "dra_4")),
    # migration 018: up to 8 actuated joints of a segment body (ra_2, dra_2 may be NULL)
    *(sa.Column(f"{p}_{i}", sa.Float) for i in range(5, 9) for p in ("ra", "dra")),
)
