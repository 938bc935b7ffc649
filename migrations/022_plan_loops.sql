-- Planned recordings (`suds-exp plan loop`): one row per closed loop and one per
-- iteration. A loop is found again by its name (a hash of its recipe without the
-- budget), so the same command after an interruption, or with a larger budget, continues.

-- One row per loop; `definition` (JSON text) holds its recipe (goal, bound, seed,
-- learner, frequency, cycles per trial, target files).
CREATE SEQUENCE plan_loops_id START 1;
CREATE TABLE plan_loops (
    id INTEGER PRIMARY KEY DEFAULT nextval('plan_loops_id'),
    name VARCHAR NOT NULL UNIQUE,       -- the loop's key: hash of its recipe
    prep_version INTEGER NOT NULL,
    goal VARCHAR NOT NULL CHECK (goal IN ('gait', 'map')),
    bound_rad DOUBLE NOT NULL,
    seed INTEGER NOT NULL,
    definition VARCHAR NOT NULL,
    created_at TIMESTAMP NOT NULL
);

-- One row per iteration, written in one transaction once its trial is recorded and the
-- map refitted: iteration 0 is the start (the warm-up recording, or the existing
-- version); each later one the trial the planner asked for, why, and where the loop stood
-- after learning it.
CREATE TABLE plan_iterations (
    loop_id INTEGER NOT NULL,
    iteration INTEGER NOT NULL,
    trial_id INTEGER,                   -- the recorded trial (NULL for an existing version)
    trial_gait VARCHAR NOT NULL,        -- a declared level's gait, or the gait file's name
    trial_frequency_hz DOUBLE NOT NULL,
    trial_cycles INTEGER NOT NULL,      -- cycles recorded in this iteration
    reason VARCHAR NOT NULL,
    score DOUBLE,                       -- mm^2 of variance removed (map) or mm/cycle expected improvement (gait)
    cycles_recorded INTEGER NOT NULL,   -- cycles the loop recorded so far, warm-up included (the budget's count)
    cycles_total INTEGER NOT NULL,      -- cycles in the version's data so far
    map_error_mm DOUBLE NOT NULL,       -- RMS distance of predicted from simulated net displacement per cycle over the target set
    best_gait VARCHAR NOT NULL,         -- JSON: name, phase_rad, phi1_rad, phi2_rad (and coefficients of a Fourier gait)
    predicted_forward_mm DOUBLE NOT NULL, -- the best gait's forward displacement per cycle, learned map
    achieved_forward_mm DOUBLE NOT NULL,  -- the same on the simulator (nominal, gait followed exactly)
    trust_radius DOUBLE,                -- rad, the gait goal's trust region for the next trial
    stop_signal BOOLEAN NOT NULL,       -- the learning curve said more data of this kind will not help
    stop_reason VARCHAR NOT NULL,
    seconds DOUBLE NOT NULL,
    UNIQUE (loop_id, iteration)
);
