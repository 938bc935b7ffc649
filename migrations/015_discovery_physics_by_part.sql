-- What the learned correction resembles on the body velocity (vx, vy, wz) and on the
-- passive shape (r_p) apart (suds_exp/discrepancy/discover.py, Discovery.physics_by_part):
-- an effect acts on one and shows in the other, so the two may read differently.
-- '' where that part has no term; NULL on rows written before this migration.
ALTER TABLE discrepancy_discoveries ADD COLUMN physics_body VARCHAR;
ALTER TABLE discrepancy_discoveries ADD COLUMN physics_passive VARCHAR;
