-- Captures and their marker tracks.
CREATE SEQUENCE trials_id_seq START 1;

CREATE TABLE trials (
    id INTEGER PRIMARY KEY DEFAULT nextval('trials_id_seq'),
    source_file VARCHAR NOT NULL,
    content_hash VARCHAR NOT NULL UNIQUE,
    format VARCHAR NOT NULL,
    gait VARCHAR,
    frequency_hz DOUBLE,
    "repeat" INTEGER,
    sample_rate_hz DOUBLE NOT NULL,
    n_frames INTEGER NOT NULL,
    marker_names VARCHAR[] NOT NULL,
    layout VARCHAR,
    ingested_at TIMESTAMP NOT NULL DEFAULT current_timestamp,
    notes VARCHAR
);

-- Long format: one row per trial, frame and marker. No index, so later migrations can
-- alter it; uniqueness follows from ingesting each trial once, in one transaction.
CREATE TABLE markers (
    trial_id INTEGER NOT NULL,
    frame INTEGER NOT NULL,
    t DOUBLE NOT NULL,
    marker VARCHAR NOT NULL,
    x DOUBLE,
    y DOUBLE,
    z DOUBLE,
    missing BOOLEAN NOT NULL
);
