-- The learner vocabulary: one row per named learner, the same rows as the registry in
-- suds_exp/models/registry.py (a test keeps the two equal). Views that label results by
-- learner read it instead of spelling learner names. Names not listed (sklearn:Class
-- learners) get NULL columns; their SUDS flag is read from the name's +SUDS suffix.
CREATE TABLE learners (
    name VARCHAR PRIMARY KEY,
    family VARCHAR NOT NULL,
    suds BOOLEAN NOT NULL,
    paper BOOLEAN NOT NULL,
    survey BOOLEAN NOT NULL,
    online BOOLEAN NOT NULL,
    baseline BOOLEAN NOT NULL
);

INSERT INTO learners VALUES
    ('phase-only', 'phase-only', false, true, true, false, false),
    ('TLS', 'TLS', false, true, true, false, false),
    ('TLS+SUDS', 'TLS', true, true, true, false, false),
    ('GMR', 'GMR', false, true, true, false, false),
    ('GMR+SUDS', 'GMR', true, true, true, false, false),
    ('MLP', 'MLP', false, false, true, false, true),
    ('MLP+SUDS', 'MLP', true, false, true, false, true),
    ('GBT', 'GBT', false, false, true, false, true),
    ('GBT+SUDS', 'GBT', true, false, false, false, true),
    ('kNN', 'kNN', false, false, true, false, true),
    ('kNN+SUDS', 'kNN', true, false, false, false, true),
    ('KRR', 'KRR', false, false, true, false, true),
    ('KRR+SUDS', 'KRR', true, false, false, false, true),
    ('OnlineGMR', 'GMR', false, false, false, true, false),
    ('OnlineGMR+SUDS', 'GMR', true, false, false, true, false),
    ('GradualGMR+SUDS', 'GMR', true, false, false, true, false);

-- `results_labelled` (migration 004) with its learner labels read from `learners`: gmr is
-- a paper learner of the GMR family, phase_only the paper's phase-only learner. The same
-- values as before for every name a campaign can store.
CREATE OR REPLACE VIEW results_labelled AS
SELECT
    r.*,
    abs(gm.position - gd.position) AS gait_steps,
    CASE
        WHEN gm.position IS NULL OR gd.position IS NULL THEN NULL
        WHEN gm.position = gd.position THEN 'same'
        WHEN abs(gm.position - gd.position) = 1 THEN 'near'
        ELSE 'far'
    END AS gait_sim,
    CASE
        WHEN round(r.train_frequency_hz, 6) = round(r.test_frequency_hz, 6) THEN '='
        WHEN r.train_frequency_hz > r.test_frequency_hz THEN '<'
        ELSE '>'
    END AS period_rel,
    CASE
        WHEN round(r.train_frequency_hz, 6) = round(r.test_frequency_hz, 6) THEN 'same'
        ELSE 'different'
    END AS freq_sim,
    1.0 / r.train_frequency_hz AS model_period_s,
    1.0 / r.test_frequency_hz AS data_period_s,
    coalesce(l.suds, r.model LIKE '%+SUDS') AS suds,
    coalesce(l.paper AND l.family = 'GMR', false) AS gmr,
    coalesce(l.paper AND l.family = 'phase-only', false) AS phase_only,
    CASE WHEN r.rmse_vx > 0 THEN ln(r.rmse_vx) END AS ln_rmse_vx
FROM results AS r
LEFT JOIN gait_axis AS gm ON gm.gait = r.train_gait
LEFT JOIN gait_axis AS gd ON gd.gait = r.test_gait
LEFT JOIN learners AS l ON l.name = r.model;
