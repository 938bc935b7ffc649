-- Analysis views over `results` (migration 003): the labels the paper's results section
-- groups by, so any SQL client (the stock `duckdb` CLI included) gets them without Python.
-- Plain SQL only: no macros, extensions or temporary objects.

-- The gait axis S+, S-, O, D-, D+; gait similarity is the distance along it.
CREATE VIEW gait_axis AS
SELECT * FROM (VALUES ('S+', 0), ('S-', 1), ('O', 2), ('D-', 3), ('D+', 4)) AS axis(gait, position);

-- One row per result, labelled. The model is the training condition, the data the test one;
-- period = 1 / frequency, so model-period < data-period means training faster than testing.
-- Frequencies are compared after rounding to 6 decimals, as `results` stores them.
CREATE VIEW results_labelled AS
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
    r.model LIKE '%+SUDS' AS suds,
    r.model LIKE 'GMR%' AS gmr,
    r.model = 'phase-only' AS phase_only,
    CASE WHEN r.rmse_vx > 0 THEN ln(r.rmse_vx) END AS ln_rmse_vx
FROM results AS r
LEFT JOIN gait_axis AS gm ON gm.gait = r.train_gait
LEFT JOIN gait_axis AS gd ON gd.gait = r.test_gait;

-- Box-plot numbers: ln RMS error of vx by learner, training size and similarity category.
CREATE VIEW results_categories AS
SELECT
    campaign,
    model,
    n_cycles,
    freq_sim,
    gait_sim,
    count(ln_rmse_vx) AS n,
    quantile_cont(ln_rmse_vx, 0.25) AS q1_ln_rmse_vx,
    quantile_cont(ln_rmse_vx, 0.5) AS median_ln_rmse_vx,
    quantile_cont(ln_rmse_vx, 0.75) AS q3_ln_rmse_vx,
    quantile_cont(rmse_vx, 0.5) AS median_rmse_vx
FROM results_labelled
GROUP BY ALL;

-- Spread table (the paper's IQR table): RMS error of vx by frequency, learner and number of
-- training cycles. `pairs` says which train/test pairs are pooled: 'same-condition' (same
-- gait and frequency: the campaign's sample-efficiency sweep; what the report uses) or
-- 'same-frequency' (any gaits at the same frequency).
CREATE VIEW results_iqr AS
SELECT
    campaign,
    pairs,
    test_frequency_hz AS frequency_hz,
    model,
    n_cycles,
    count(rmse_vx) AS n,
    quantile_cont(rmse_vx, 0.25) AS q1,
    quantile_cont(rmse_vx, 0.5) AS median,
    quantile_cont(rmse_vx, 0.75) AS q3,
    quantile_cont(rmse_vx, 0.75) - quantile_cont(rmse_vx, 0.25) AS iqr
FROM (
    SELECT 'same-condition' AS pairs, * FROM results_labelled
    WHERE freq_sim = 'same' AND gait_sim = 'same'
    UNION ALL
    SELECT 'same-frequency' AS pairs, * FROM results_labelled
    WHERE freq_sim = 'same'
) AS pooled
GROUP BY ALL;
