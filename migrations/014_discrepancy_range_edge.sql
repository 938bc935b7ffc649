-- A named effect whose fitted value is pinned at a bound of its realistic range is also
-- reported as a partial explanation (suds_exp/discrepancy/partial.py, at_range_edge):
-- the data want more of it than the physics allows. discrepancy_steps.decision is then
-- `partial` even when `significant` (the varying-strength test) is false.
ALTER TABLE discrepancy_constancy ADD COLUMN at_range_edge BOOLEAN DEFAULT FALSE;
