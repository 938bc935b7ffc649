-- Cause or partial explanation (suds_exp/discrepancy/partial.py): after a named effect is
-- added, the next replay gives its contribution D, and a held-out test asks whether
-- letting D's strength vary with distance travelled, time in the trial or sliding
-- direction removes a material part of what remains. One row per named effect checked.
-- When `significant`, the effect's discrepancy_steps.decision is `partial`: kept in the
-- model, reported as a partial explanation, not as the cause.

CREATE TABLE discrepancy_constancy (
    run_id INTEGER NOT NULL,
    step INTEGER NOT NULL,              -- the step of discrepancy_steps that named it
    effect VARCHAR NOT NULL,            -- candidate label
    significant BOOLEAN NOT NULL,       -- strength not constant, at the run's alpha
    p_value DOUBLE,
    test_loss_constant DOUBLE,          -- held-out loss, D re-scaled by one constant
    test_loss_varying DOUBLE,           -- same, D varying along distance, time, direction
    varies_with VARCHAR,                -- family of the largest varying term
    PRIMARY KEY (run_id, step)
);
