-- Your experiment's own conditions (suds_exp.experiment): the axes a user declares and
-- each trial's value along them. Trials ingested with the paper's design (the default)
-- get no rows here: their gait and frequency_hz columns say it all, and every existing
-- view reads those. With a user design `trials.gait` holds the condition label
-- (e.g. `gait=wave-1;amplitude=0.8`) and these tables the values behind it.

-- One row per declared axis, `position` its order of declaration; `levels` is the ordered
-- or unordered categories (JSON list, NULL for numeric). Ingests with a design add their
-- axes; a different declaration of an axis already stored is refused.
CREATE TABLE experiment_axes (
    axis VARCHAR PRIMARY KEY,
    position INTEGER NOT NULL,
    kind VARCHAR NOT NULL CHECK (kind IN ('ordered', 'numeric', 'unordered')),
    levels VARCHAR
);

-- The ordered and unordered levels, with their position along the axis.
CREATE TABLE experiment_levels (
    axis VARCHAR NOT NULL,
    level VARCHAR NOT NULL,
    position INTEGER NOT NULL,
    UNIQUE (axis, level)
);

-- One row per trial and declared axis: the text value and, for numeric axes, the number.
CREATE TABLE trial_conditions (
    trial_id INTEGER NOT NULL,
    axis VARCHAR NOT NULL,
    value VARCHAR NOT NULL,
    value_num DOUBLE,
    UNIQUE (trial_id, axis)
);

-- Condition (label, frequency rounded to 6 decimals, as `results` stores it) -> its value
-- along each axis, from the trials that carry it.
CREATE VIEW condition_values AS
SELECT DISTINCT
    t.gait AS label,
    round(t.frequency_hz, 6) AS frequency_hz,
    c.axis,
    a.kind,
    c.value,
    c.value_num,
    l.position
FROM trials AS t
JOIN trial_conditions AS c ON c.trial_id = t.id
JOIN experiment_axes AS a ON a.axis = c.axis
LEFT JOIN experiment_levels AS l ON l.axis = c.axis AND l.level = c.value;

-- One row per result of a user design and axis: the pair's category along the axis
-- (ordered: same / near / far; numeric: same / lower / higher, trained at a lower or higher
-- value than tested; unordered: same / different).
CREATE VIEW results_axis_pairs AS
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
        WHEN m.kind = 'ordered' AND m.position = d.position THEN 'same'
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
