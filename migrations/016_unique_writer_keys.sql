-- Unique keys behind the database's write lock (suds_exp/store/lock.py): every writing
-- command holds the lock, so these never fire in normal use; they are the last line of
-- defence, turning a second writer's duplicate into a refused transaction.
-- (Numbered 016 by issue 33: other migrations may be added around it.)
--
-- Databases written before the lock may hold duplicates already: two `preprocess` runs
-- racing stored a trial's samples twice (identical rows: the same version's fits), two
-- `discrepancy` runs could share a name. The first copy of each sample and trial row is
-- kept; a repeated run name gets its run id as a suffix (no run is lost). DuckDB cannot
-- build an index over rows deleted or updated in the same transaction, so the two
-- tables are rebuilt with the key instead of altered.

DELETE FROM samples WHERE rowid IN (
    SELECT rowid FROM (
        SELECT s.rowid AS rowid,
               row_number() OVER (PARTITION BY s.version_id, s.trial_id, s.frame
                                  ORDER BY s.rowid) AS copy
        FROM samples s
        SEMI JOIN (
            SELECT version_id, trial_id FROM prep_trials
            GROUP BY version_id, trial_id HAVING count(*) > 1
        ) d ON s.version_id = d.version_id AND s.trial_id = d.trial_id
    ) WHERE copy > 1
);

-- One row per (version, trial): written in the transaction of the trial's samples, so
-- it also keeps a trial's samples from being stored twice.
CREATE TABLE prep_trials_016 (
    version_id INTEGER NOT NULL,
    trial_id INTEGER NOT NULL,
    n_frames INTEGER NOT NULL,
    n_jumps INTEGER NOT NULL,
    removed_fraction DOUBLE NOT NULL,
    filled_fraction DOUBLE NOT NULL,
    longest_gap_frames INTEGER NOT NULL,
    plane_normal DOUBLE[] NOT NULL,
    middle_length_mm DOUBLE NOT NULL,
    joint_rms_mm DOUBLE NOT NULL,
    phaser_group VARCHAR NOT NULL,
    done_at TIMESTAMP NOT NULL DEFAULT current_timestamp,
    UNIQUE (version_id, trial_id)
);
INSERT INTO prep_trials_016
SELECT * EXCLUDE (copy) FROM (
    SELECT *, row_number() OVER (PARTITION BY version_id, trial_id ORDER BY rowid) AS copy
    FROM prep_trials
) WHERE copy = 1;
DROP TABLE prep_trials;
ALTER TABLE prep_trials_016 RENAME TO prep_trials;

-- One stored run per name (a run's report folder is named after it).
CREATE TABLE discrepancy_runs_016 (
    id INTEGER PRIMARY KEY DEFAULT nextval('discrepancy_runs_id_seq'),
    name VARCHAR NOT NULL UNIQUE,
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
INSERT INTO discrepancy_runs_016
SELECT * EXCLUDE (first_id)
       REPLACE (CASE WHEN id = first_id THEN name ELSE name || '-' || id END AS name)
FROM (SELECT *, min(id) OVER (PARTITION BY name) AS first_id FROM discrepancy_runs);
DROP TABLE discrepancy_runs;
ALTER TABLE discrepancy_runs_016 RENAME TO discrepancy_runs;
