-- The Finsler learner of suds_exp/models/tls_finsler.py in the learner vocabulary (the
-- registry of suds_exp/models/registry.py; a test keeps the two equal). Untagged, like
-- GMR+F.
INSERT INTO learners VALUES
    ('TLS+F', 'TLS', false, false, false, false, false);
