"""What the SUDS variants of the learners share: their prediction modes and r_p columns.

A SUDS variant adds the passive shape r_p (columns ``rp_1..rp_k``) to its inputs and
predicts either from the measured r_p ("measured") or from r_p integrated along each trial
with its own dr_p/dt ("rollout").
"""

from __future__ import annotations

import pandas as pd

from suds_exp.models.base import ModelError, check_choice, passive_columns
from suds_exp.models.params import Options, Param

#: How a SUDS variant gets r_p at predict time.
MODES = ("measured", "rollout")
#: What a SUDS variant adds to its learner's hyper-parameters.
SUDS_PARAMETERS = {"mode": Param("measured", Options(MODES))}


def check_mode(mode: str, model: str) -> str:
    """`mode` if it is one of `MODES`, else a ConfigError naming `model`."""
    return check_choice("mode", mode, MODES, model)


def required_passive_columns(samples: pd.DataFrame, model: str) -> tuple[list[str], list[str]]:
    """(rp columns, drp columns) of `samples`; a ModelError naming `model` if it has no r_p."""
    rp, drp = passive_columns(samples)
    if not rp:
        raise ModelError(f"{model}: samples frame has no rp_1.. columns (passive shape)")
    return rp, drp
