"""Data with a known truth and the demo built on it, for tests, benchmarks and `suds-exp demo`.

- `synthetic_captures`: marker captures of a rigid 3-segment robot with known kinematics;
- `synthetic_swimmer`: samples frames of a swimmer with a known motility map;
- `synthetic_results`: `results` rows with planted effects of known size;
- `hidden_effects`: simulated "measured" data with effects hidden from the discrepancy
  workflow;
- `demo_campaign`, `demo`: the small campaign and the whole pipeline of `suds-exp demo`.

Nothing here is imported by the library below it.
"""
