-- Prequential streams (`suds-exp stream`): their definitions and one row per scored cycle.

-- One row per stream; `definition` (JSON text) is what a continuation must match.
CREATE TABLE streams (
    name VARCHAR PRIMARY KEY,
    prep_version VARCHAR NOT NULL,
    definition VARCHAR NOT NULL,
    created_at TIMESTAMP NOT NULL
);

-- One row per (stream, learner, trial, cycle) scored before the learner saw it.
-- Cycles are numbered 0.. in time order within the trial; times in s from the trial start.
CREATE TABLE stream_cycles (
    stream VARCHAR NOT NULL,
    model VARCHAR NOT NULL,
    trial_id INTEGER NOT NULL,
    cycle INTEGER NOT NULL,
    t_start DOUBLE NOT NULL,
    t_end DOUBLE NOT NULL,
    change_s DOUBLE,                    -- scheduled change of the trial, s (NULL: none)
    n_samples INTEGER NOT NULL,
    rmse_vx DOUBLE NOT NULL,            -- mm/s
    rmse_vy DOUBLE NOT NULL,            -- mm/s
    rmse_wz DOUBLE NOT NULL,            -- rad/s
    rms_vx DOUBLE NOT NULL,             -- RMS of the measured vx in the cycle, mm/s
    ph_stat DOUBLE NOT NULL,            -- Page-Hinkley statistic after this cycle
    alarm BOOLEAN NOT NULL,             -- the drift alarm fired at this cycle
    learn_seconds DOUBLE NOT NULL,      -- partial_fit on this cycle (0: batch learner)
    predict_seconds DOUBLE NOT NULL,
    UNIQUE (stream, model, trial_id, cycle)
);
