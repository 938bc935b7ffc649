-- Trials recorded by code rather than by the user (a planning loop's warm-up and its
-- trials, `suds_exp.ingest.added.mark_trials_added`): who recorded them. A condition
-- every trial of which code recorded is one the campaign leaves out where it cannot
-- supply it, as it does an added level, without the campaign reading plan tables.
CREATE TABLE trials_added (
    trial_id INTEGER PRIMARY KEY,
    added_by VARCHAR NOT NULL           -- e.g. 'plan loop plan-0123456789ab'
);

-- The trials plan loops recorded before this migration.
INSERT INTO trials_added
SELECT i.trial_id, 'plan loop ' || min(l.name)
FROM plan_iterations AS i
JOIN plan_loops AS l ON l.id = i.loop_id
WHERE i.trial_id IS NOT NULL
GROUP BY i.trial_id;
