"""Data with a known truth, for tests, benchmarks and the docs.

- `synthetic_captures`: marker captures of a rigid 3-segment robot with known kinematics;
- `synthetic_swimmer`: samples frames of a swimmer with a known motility map;
- `synthetic_results`: `results` rows with planted effects of known size;
- `kinematic_body`: planar bodies of rigid segments (random joint trees) and their captures.
- `synthetic_samples`: a samples frame whose body velocity is a known quadratic map;
- `capture_files`: C3D, TRC, Vicon Nexus and Motive files written from marker arrays;
- `database`: whole-database snapshots (`dump_db`) and their comparison (`assert_same_db`);
- `migration_text`: the tables and views the migrations' SQL text creates;
- `reliability_probe`: every writing command killed, raced and fed bad input through the
  command line (`python -m suds_exp.testing.reliability_probe`).

It sits just above what it fakes (bodies, captures, learners' results) and below the
analyses that read such data; the pipelines built on it (the demo, the hidden-effect
runs) are `suds_exp.workflows`. Nothing here is imported by the library below it.
"""
