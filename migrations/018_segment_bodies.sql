-- Any body of rigid segments (suds_exp.body.SegmentModel): r_a is its actuated joints'
-- angles, one to eight of them. A body with one actuated joint leaves ra_2, dra_2 NULL;
-- up to eight fill ra_5 .. ra_8. Versions of the swimmer leave the new columns NULL.
ALTER TABLE samples ALTER COLUMN ra_2 DROP NOT NULL;
ALTER TABLE samples ALTER COLUMN dra_2 DROP NOT NULL;
ALTER TABLE samples ADD COLUMN ra_5 DOUBLE;
ALTER TABLE samples ADD COLUMN dra_5 DOUBLE;
ALTER TABLE samples ADD COLUMN ra_6 DOUBLE;
ALTER TABLE samples ADD COLUMN dra_6 DOUBLE;
ALTER TABLE samples ADD COLUMN ra_7 DOUBLE;
ALTER TABLE samples ADD COLUMN dra_7 DOUBLE;
ALTER TABLE samples ADD COLUMN ra_8 DOUBLE;
ALTER TABLE samples ADD COLUMN dra_8 DOUBLE;
