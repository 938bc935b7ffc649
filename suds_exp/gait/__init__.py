"""Gaits: read any gait, predict its motion from a learned map, see the learned
connection, design a better gait and verify it on the simulator.

Public face (the CLI's `gait predict | design | connection` and `simulate --gait-file`
are thin faces on these):

- `read_gait_file(path, bound)`, `FourierGait`, `SampledGait`, `ellipse`,
  `paper_gaits()` (`shape`): a gait as a closed joint path over one cycle, one column per
  actuated joint named as the body's joints; `version_joints`, `match_joints` (`joints`):
  a version's actuated joints and a gait matched to them by name.
- `simulate_gaits(gaits, frequency_hz)` (`truth`): the simulator's net motion per cycle.
- `predict_gait(store, prep, learner, gait, frequency_hz)`, `predict_gaits(samples, ...)`,
  `fit_map` (`predict`): a learned map's prediction by the SE(2) path-ordered integral,
  with percentile intervals (`percentile_interval`) and the gait's support flag
  (`Support.flag`, `support`).
- `learned_connection(model, samples)`, `compare_connections` (`connection`), drawn by
  `draw_connection` (`plots`).
- `design_gait(store, prep, DesignOptions(...))` (`design`): the design loop, stored.
- `simulate_gait_file(out, gait, ...)` (`trials`): capture sessions of a gait file.
"""

from suds_exp.gait.connection import LearnedConnection, compare_connections, learned_connection
from suds_exp.gait.design import Design, DesignOptions, design_gait, load_design
from suds_exp.gait.joints import match_joints, version_joints
from suds_exp.gait.motion import CycleMotion, integrate_twists
from suds_exp.gait.predict import (
    GaitPrediction,
    fit_map,
    percentile_interval,
    predict_gait,
    predict_gaits,
)
from suds_exp.gait.shape import (
    FourierGait,
    Gait,
    SampledGait,
    ellipse,
    paper_gaits,
    read_gait_file,
    within_bound,
)
from suds_exp.gait.trials import simulate_gait_file
from suds_exp.gait.truth import simulate_forward, simulate_gaits

__all__ = [
    "CycleMotion",
    "Design",
    "DesignOptions",
    "FourierGait",
    "Gait",
    "GaitPrediction",
    "LearnedConnection",
    "SampledGait",
    "compare_connections",
    "design_gait",
    "ellipse",
    "fit_map",
    "integrate_twists",
    "learned_connection",
    "load_design",
    "match_joints",
    "paper_gaits",
    "percentile_interval",
    "predict_gait",
    "predict_gaits",
    "read_gait_file",
    "simulate_forward",
    "simulate_gait_file",
    "simulate_gaits",
    "version_joints",
    "within_bound",
]
