-- Preprocessing: versions (parameter sets), their fitted state, per-trial stats, samples.
CREATE SEQUENCE prep_versions_id_seq START 1;

-- One row per parameter set: the same parameters (canonical JSON, SHA-256) are one version.
CREATE TABLE prep_versions (
    id INTEGER PRIMARY KEY DEFAULT nextval('prep_versions_id_seq'),
    name VARCHAR NOT NULL UNIQUE,
    params_hash VARCHAR NOT NULL UNIQUE,
    params VARCHAR NOT NULL,
    k INTEGER NOT NULL,
    created_at TIMESTAMP NOT NULL DEFAULT current_timestamp
);

-- Fitted state of a version, as JSON: kind 'joints' and 'pca' (grp ''), 'phaser' (one per
-- trial group, e.g. 'O@0.5').
CREATE TABLE prep_fits (
    version_id INTEGER NOT NULL,
    kind VARCHAR NOT NULL,
    grp VARCHAR NOT NULL,
    state VARCHAR NOT NULL,
    trial_ids INTEGER[] NOT NULL,
    n_frames INTEGER NOT NULL,
    fitted_at TIMESTAMP NOT NULL DEFAULT current_timestamp,
    PRIMARY KEY (version_id, kind, grp)
);

-- The passive PCA of a version, one row per principal component (all 12 kept here).
CREATE TABLE prep_pca (
    version_id INTEGER NOT NULL,
    component INTEGER NOT NULL,
    explained_variance DOUBLE NOT NULL,
    explained_variance_ratio DOUBLE NOT NULL,
    cumulative_ratio DOUBLE NOT NULL,
    kept BOOLEAN NOT NULL,
    loadings DOUBLE[] NOT NULL
);

-- One row per (version, trial) done; written in the transaction that writes its samples.
CREATE TABLE prep_trials (
    version_id INTEGER NOT NULL,
    trial_id INTEGER NOT NULL,
    n_frames INTEGER NOT NULL,
    n_jumps INTEGER NOT NULL,
    removed_fraction DOUBLE NOT NULL,
    filled_fraction DOUBLE NOT NULL,
    longest_gap_frames INTEGER NOT NULL,
    plane_normal DOUBLE[] NOT NULL,
    middle_length_mm DOUBLE NOT NULL,
    joint_rms_mm DOUBLE NOT NULL,
    phaser_group VARCHAR NOT NULL,
    done_at TIMESTAMP NOT NULL DEFAULT current_timestamp
);

-- One row per trial frame per version. rp_i / drp_i hold the first k passive components
-- (NULL above k). No index, so later migrations may alter it.
CREATE TABLE samples (
    version_id INTEGER NOT NULL,
    trial_id INTEGER NOT NULL,
    frame INTEGER NOT NULL,
    t DOUBLE NOT NULL,
    phase DOUBLE NOT NULL,
    cycle INTEGER NOT NULL,
    ra_1 DOUBLE NOT NULL,
    ra_2 DOUBLE NOT NULL,
    dra_1 DOUBLE NOT NULL,
    dra_2 DOUBLE NOT NULL,
    rp_1 DOUBLE,
    rp_2 DOUBLE,
    rp_3 DOUBLE,
    rp_4 DOUBLE,
    rp_5 DOUBLE,
    rp_6 DOUBLE,
    rp_7 DOUBLE,
    rp_8 DOUBLE,
    rp_9 DOUBLE,
    rp_10 DOUBLE,
    rp_11 DOUBLE,
    rp_12 DOUBLE,
    drp_1 DOUBLE,
    drp_2 DOUBLE,
    drp_3 DOUBLE,
    drp_4 DOUBLE,
    drp_5 DOUBLE,
    drp_6 DOUBLE,
    drp_7 DOUBLE,
    drp_8 DOUBLE,
    drp_9 DOUBLE,
    drp_10 DOUBLE,
    drp_11 DOUBLE,
    drp_12 DOUBLE,
    vx DOUBLE NOT NULL,
    vy DOUBLE NOT NULL,
    wz DOUBLE NOT NULL
);
