"""End-to-end pipelines that chain the boxes below: simulate then ingest, the demo, and
the hidden-effect runs of the discrepancy checks.

- `simulate`: `simulate_and_ingest`, the simulator's files ingested as a capture system's;
- `demo`, `demo_campaign`: `suds-exp demo` (a summary back, its narration through a
  callback: the command layer prints);
- `hidden_effects`: simulated "measured" data with effects hidden from the discrepancy
  workflow.
"""
