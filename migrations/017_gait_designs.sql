-- Gait design (`suds-exp gait design`): one row per design run and one per iteration.

-- One row per design run; `definition` (JSON text) holds its options (learner, bound,
-- order, frequency, iterations, verify, trust-region settings).
CREATE SEQUENCE gait_designs_id START 1;
CREATE TABLE gait_designs (
    id INTEGER PRIMARY KEY DEFAULT nextval('gait_designs_id'),
    prep_version INTEGER NOT NULL,
    learner VARCHAR NOT NULL,
    bound_rad DOUBLE NOT NULL,
    frequency_hz DOUBLE NOT NULL,
    definition VARCHAR NOT NULL,
    created_at TIMESTAMP NOT NULL
);

-- One row per iteration: the designed gait (Fourier coefficients as JSON text, the path
-- over one cycle as lists), what the learned map predicted, what the simulator achieved
-- (NULL without --verify), the trust radius and the training data's support it used,
-- and the verify trial it added to the version (NULL without --verify).
CREATE TABLE gait_design_iterations (
    design_id INTEGER NOT NULL,
    iteration INTEGER NOT NULL,
    gait VARCHAR NOT NULL,              -- JSON: name, coefficients, phase_rad, phi1_rad, phi2_rad
    predicted_forward_mm DOUBLE NOT NULL,
    predicted_lateral_mm DOUBLE NOT NULL,
    predicted_turn_rad DOUBLE NOT NULL,
    predicted_mean_vx_mm_s DOUBLE NOT NULL,
    achieved_forward_mm DOUBLE,
    achieved_lateral_mm DOUBLE,
    achieved_turn_rad DOUBLE,
    achieved_mean_vx_mm_s DOUBLE,
    trust_radius DOUBLE NOT NULL,       -- rad, (shape, direction) metric of suds_exp.gait.support
    support_distance DOUBLE NOT NULL,   -- rad, the gait's distance from the training data
    support VARCHAR NOT NULL,           -- JSON: training samples, trial ids, shape range
    trial_id INTEGER,                   -- the verify trial (NULL without --verify)
    seconds DOUBLE NOT NULL,
    UNIQUE (design_id, iteration)
);
