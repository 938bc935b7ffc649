-- Discrepancy workflow: runs, their steps (model at each step and the decision taken),
-- every candidate tried at every step, and the localisation views of each step.

CREATE SEQUENCE discrepancy_runs_id_seq START 1;

-- One row per `suds-exp discrepancy` run. JSON columns hold text.
CREATE TABLE discrepancy_runs (
    id INTEGER PRIMARY KEY DEFAULT nextval('discrepancy_runs_id_seq'),
    name VARCHAR NOT NULL,
    prep_version VARCHAR,
    start_model VARCHAR NOT NULL,       -- JSON of the starting SimConfig
    final_model VARCHAR,                -- JSON of the model after the accepted effects
    options VARCHAR NOT NULL,           -- JSON: alpha, max_effects, seed, replay and fit settings
    train_trials VARCHAR NOT NULL,      -- JSON list of trial ids
    test_trials VARCHAR NOT NULL,       -- JSON list of trial ids
    named_effects VARCHAR,              -- JSON list of accepted candidate labels, in order
    outcome VARCHAR,                    -- one-line conclusion
    report_dir VARCHAR,
    seconds DOUBLE,
    started_at TIMESTAMP NOT NULL,
    finished_at TIMESTAMP
);

-- One row per step: the model replayed, its held-out gap, and what was decided.
CREATE TABLE discrepancy_steps (
    run_id INTEGER NOT NULL,
    step INTEGER NOT NULL,
    model VARCHAR NOT NULL,             -- JSON SimConfig replayed at this step
    test_loss DOUBLE NOT NULL,          -- mean normalised squared residual, held-out trials
    test_rmse_vx DOUBLE NOT NULL,       -- mm/s
    test_rmse_vy DOUBLE NOT NULL,       -- mm/s
    test_rmse_wz DOUBLE NOT NULL,       -- rad/s
    n_candidates INTEGER NOT NULL,
    decision VARCHAR NOT NULL,          -- accepted | none_significant | max_effects
    accepted VARCHAR,                   -- candidate label
    parameter VARCHAR,
    value DOUBLE,
    ci_low DOUBLE,
    ci_high DOUBLE,
    unit VARCHAR,
    p_adjusted DOUBLE,
    gap_closed DOUBLE,                  -- fraction of the held-out loss removed
    systematic_z DOUBLE,                -- split-half phase-profile agreement of the residual
    systematic_p DOUBLE,
    correlations VARCHAR,               -- JSON [[channel, signal, r], ...] when unexplained
    PRIMARY KEY (run_id, step)
);

-- One row per candidate tried at a step.
CREATE TABLE discrepancy_candidates (
    run_id INTEGER NOT NULL,
    step INTEGER NOT NULL,
    candidate VARCHAR NOT NULL,
    effect VARCHAR NOT NULL,
    parameter VARCHAR,
    value DOUBLE,
    ci_low DOUBLE,
    ci_high DOUBLE,
    unit VARCHAR,
    train_loss_before DOUBLE,
    train_loss_after DOUBLE,
    test_loss_before DOUBLE,
    test_loss_after DOUBLE,
    improvement DOUBLE,                 -- 1 - after / before, held-out
    p_value DOUBLE,
    p_adjusted DOUBLE,
    significant BOOLEAN NOT NULL,
    accepted BOOLEAN NOT NULL,
    n_replays INTEGER NOT NULL,
    seconds DOUBLE NOT NULL,
    PRIMARY KEY (run_id, step, candidate)
);

-- The localisation views of each step's model (see suds_exp/discrepancy/localise.py).
CREATE TABLE discrepancy_localisation (
    run_id INTEGER NOT NULL,
    step INTEGER NOT NULL,
    view VARCHAR NOT NULL,              -- condition | phase | shape | time
    gait VARCHAR,
    frequency_hz DOUBLE,
    bin INTEGER NOT NULL,
    x DOUBLE,
    y DOUBLE,
    channel VARCHAR NOT NULL,
    rms DOUBLE,
    band_lo DOUBLE,
    band_hi DOUBLE,
    n INTEGER NOT NULL
);
