-- r_a as Cartesian values (preprocessing parameter ra_repr=cartesian, preset `paper`):
-- each outer segment's top-marker centroid in the body frame, 4 values, mm. ra_1, ra_2,
-- dra_1, dra_2 keep their meaning for the joint angles; versions with joint angles leave
-- the new columns NULL.
ALTER TABLE samples ADD COLUMN ra_3 DOUBLE;
ALTER TABLE samples ADD COLUMN ra_4 DOUBLE;
ALTER TABLE samples ADD COLUMN dra_3 DOUBLE;
ALTER TABLE samples ADD COLUMN dra_4 DOUBLE;
