-- Discovery: the sparse learned correction fitted when no named effect explains a
-- systematic gap (suds_exp/discrepancy/discover.py). One row per run step where it was
-- tried, and one row per term of the correction. A correction is added to the model
-- (the run's final model plus these terms) only when `significant`; that step's
-- discrepancy_steps.decision is then `discovered`.

CREATE TABLE discrepancy_discoveries (
    run_id INTEGER NOT NULL,
    step INTEGER NOT NULL,              -- the step of discrepancy_steps it corrects
    significant BOOLEAN NOT NULL,       -- passed the held-out paired test at the run's alpha
    p_value DOUBLE,
    test_loss_before DOUBLE,            -- held-out loss of the step's model
    test_loss_after DOUBLE,             -- same, with the correction added
    gap_closed DOUBLE,                  -- 1 - after / before
    physics VARCHAR,                    -- what the leading term resembles (inertia, ...)
    leading_features VARCHAR,           -- JSON list of feature names, largest share first
    equations VARCHAR,                  -- JSON list of one equation per corrected channel
    n_features INTEGER NOT NULL,        -- size of the feature library
    seconds DOUBLE,
    PRIMARY KEY (run_id, step)
);

-- channel_model = channel_replay + sum over terms of coefficient * feature
CREATE TABLE discrepancy_correction_terms (
    run_id INTEGER NOT NULL,
    step INTEGER NOT NULL,
    channel VARCHAR NOT NULL,           -- vx | vy | wz | rp_k
    feature VARCHAR NOT NULL,           -- as written in the equations (e.g. dv_x/dt, s*v_x)
    family VARCHAR NOT NULL,            -- acceleration | distance | sign | rate | ...
    unit VARCHAR NOT NULL,              -- of the coefficient
    coefficient DOUBLE NOT NULL,
    ci_low DOUBLE,                      -- trial-bootstrap percentile interval
    ci_high DOUBLE,
    weight DOUBLE,                      -- term's RMS over the channel's loss scale
    PRIMARY KEY (run_id, step, channel, feature)
);
