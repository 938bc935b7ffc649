"""Plan the next recording: which trial teaches the learned map most, or brings the best
gait closest, and when more data of a kind stops helping.

Public face (the CLI's `plan next | loop` are thin faces on these):

- `plan_next(store, prep, goal, Target(...))` (`advise`): the next trial(s), each with its
  reason, and the stopping signal (the map goal's forecast for the next doubling).
- `run_loop(store, LoopOptions(...))` (`loop`): the closed loop with the simulator as the
  robot, every iteration stored (``plan_iterations``); rerunning continues it.
- `MapEnsemble` (`ensemble`): a learner, its cycle-bootstrap refits and its
  path-jackknife refits, the uncertainty every plan reads; `forecast_signal` (the map
  goal's stopping signal), `learning_curve`, `target_signal` (`curve`); `Target`,
  `unseen_gaits` (`target`); `recorded_gaits` (`recorded`): the gaits a version's
  trials ran, found by their files' names.
"""

from suds_exp.plan.advise import Advice, plan_next
from suds_exp.plan.curve import StopSignal, forecast_signal, learning_curve, target_signal
from suds_exp.plan.ensemble import MapEnsemble
from suds_exp.plan.loop import Loop, LoopIteration, LoopOptions, load_loop, run_loop
from suds_exp.plan.recommend import Recommendation, Trial
from suds_exp.plan.recorded import RecordedGaits, recorded_gaits
from suds_exp.plan.target import GOALS, Target, TargetTruth, unseen_gaits

__all__ = [
    "GOALS",
    "Advice",
    "Loop",
    "LoopIteration",
    "LoopOptions",
    "MapEnsemble",
    "Recommendation",
    "RecordedGaits",
    "StopSignal",
    "Target",
    "TargetTruth",
    "Trial",
    "learning_curve",
    "forecast_signal",
    "load_loop",
    "plan_next",
    "recorded_gaits",
    "run_loop",
    "target_signal",
    "unseen_gaits",
]
