-- The momentum learners of suds_exp/models/momentum.py and the Finsler learner of
-- suds_exp/models/finsler.py in the learner vocabulary (the
-- registry of suds_exp/models/registry.py; a test keeps the two equal). Untagged: they
-- are neither the paper's five, nor the survey's set, nor online, nor baselines.
INSERT INTO learners VALUES
    ('GMR+P', 'GMR', false, false, false, false, false),
    ('GMR+SUDS+P', 'GMR', true, false, false, false, false),
    ('GMR+F', 'GMR', false, false, false, false, false);
