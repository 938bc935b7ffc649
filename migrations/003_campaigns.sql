-- Bootstrap campaigns: their definitions, each run of them, and one row per finished job.

-- One row per campaign; `definition` is the JSON document a continuation must match.
CREATE TABLE campaigns (
    name VARCHAR PRIMARY KEY,
    prep_version VARCHAR NOT NULL,
    definition VARCHAR NOT NULL,
    n_jobs INTEGER NOT NULL,
    created_at TIMESTAMP NOT NULL
);

-- One row per `suds-exp run` of a campaign (append-only: rate and ETA come from here).
CREATE SEQUENCE campaign_runs_id_seq START 1;

CREATE TABLE campaign_runs (
    id INTEGER PRIMARY KEY DEFAULT nextval('campaign_runs_id_seq'),
    campaign VARCHAR NOT NULL,
    started_at TIMESTAMP NOT NULL,
    pid INTEGER NOT NULL,
    host VARCHAR NOT NULL,
    backend VARCHAR NOT NULL,
    n_workers INTEGER NOT NULL,
    n_pending INTEGER NOT NULL
);

-- One row per finished job. Frequencies are rounded to 6 decimals; JSON columns hold text.
CREATE TABLE results (
    campaign VARCHAR NOT NULL,
    model VARCHAR NOT NULL,
    train_gait VARCHAR NOT NULL,
    train_frequency_hz DOUBLE NOT NULL,
    test_gait VARCHAR NOT NULL,
    test_frequency_hz DOUBLE NOT NULL,
    boot INTEGER NOT NULL,
    n_cycles INTEGER NOT NULL,
    train_trials VARCHAR NOT NULL,
    train_ranges VARCHAR NOT NULL,
    test_trial INTEGER NOT NULL,
    test_range VARCHAR NOT NULL,
    rmse_vx DOUBLE,
    rmse_vy DOUBLE,
    rmse_wz DOUBLE,
    n_test INTEGER NOT NULL,
    fit_seconds DOUBLE NOT NULL,
    predict_seconds DOUBLE NOT NULL,
    finished_at TIMESTAMP NOT NULL,
    error VARCHAR,
    UNIQUE (campaign, model, train_gait, train_frequency_hz, test_gait, test_frequency_hz,
            boot, n_cycles)
);
