-- The experiment description kept with the data (`suds-exp ingest --experiment`), so that
-- run, report, findings and status read it without being given it again. One row once a
-- design other than the paper's is stored; none means the paper's design (the default).
-- Its axes and levels are the rows of experiment_axes / experiment_levels (020), not
-- copied here: this row says that a design was declared (also one without axes, for
-- recordings without conditions) and which file it came from.
CREATE TABLE experiment_description (
    id INTEGER PRIMARY KEY CHECK (id = 1),
    source VARCHAR NOT NULL,            -- the TOML file as named at ingest, or 'paper'
    created_at TIMESTAMP NOT NULL
);

-- A database that stored a design's axes before this migration: those axes are its
-- description (the file's name was not kept then).
INSERT INTO experiment_description
SELECT 1, 'experiment_axes (stored before migration 021)', current_timestamp
WHERE EXISTS (SELECT 1 FROM experiment_axes);

-- Levels added after the declaration by code that adds trials (the trials of
-- `gait design --verify`, a planning loop; `suds_exp.ingest.add_trial_levels`): who added
-- them. NULL for a declared level. An added level of an ordered axis has no place in the
-- declared order: a pair with it is `same` (the same level) or `far`, never `near`.
ALTER TABLE experiment_levels ADD COLUMN added_by VARCHAR;

-- As in 020, with `added_by`, and no position for added levels (see above).
CREATE OR REPLACE VIEW condition_values AS
SELECT DISTINCT
    t.gait AS label,
    round(t.frequency_hz, 6) AS frequency_hz,
    c.axis,
    a.kind,
    c.value,
    c.value_num,
    CASE WHEN l.added_by IS NULL THEN l.position END AS position,
    l.added_by
FROM trials AS t
JOIN trial_conditions AS c ON c.trial_id = t.id
JOIN experiment_axes AS a ON a.axis = c.axis
LEFT JOIN experiment_levels AS l ON l.axis = c.axis AND l.level = c.value;

-- As in 020; an added level of an ordered axis is `same` only as itself, else `far`.
CREATE OR REPLACE VIEW results_axis_pairs AS
SELECT
    r.campaign,
    r.model,
    r.train_gait,
    r.train_frequency_hz,
    r.test_gait,
    r.test_frequency_hz,
    r.boot,
    r.n_cycles,
    m.axis,
    m.kind,
    m.value AS train_value,
    d.value AS test_value,
    CASE
        WHEN m.kind = 'ordered' AND m.value = d.value THEN 'same'
        WHEN m.kind = 'ordered' AND abs(m.position - d.position) = 1 THEN 'near'
        WHEN m.kind = 'ordered' THEN 'far'
        WHEN m.kind = 'numeric' AND round(m.value_num, 6) = round(d.value_num, 6) THEN 'same'
        WHEN m.kind = 'numeric' AND m.value_num < d.value_num THEN 'lower'
        WHEN m.kind = 'numeric' THEN 'higher'
        WHEN m.value = d.value THEN 'same'
        ELSE 'different'
    END AS category,
    r.rmse_vx
FROM results AS r
JOIN condition_values AS m
    ON m.label = r.train_gait AND m.frequency_hz = round(r.train_frequency_hz, 6)
JOIN condition_values AS d
    ON d.label = r.test_gait AND d.frequency_hz = round(r.test_frequency_hz, 6)
    AND d.axis = m.axis;
