"""Your experiment's own conditions: the axes a user declares (TOML), the paper's design
as the built-in default, and how a train/test pair is classified along each axis."""

from suds_exp.experiment.design import (
    BY_TRIAL_LABEL,
    FREQUENCY_AXIS,
    KINDS,
    PAPER_DESIGN,
    Axis,
    ExperimentDesign,
    design_from_dict,
    is_paper,
    load_design,
)
from suds_exp.experiment.pairs import classify, classify_pair, pair_column

__all__ = [
    "BY_TRIAL_LABEL",
    "FREQUENCY_AXIS",
    "KINDS",
    "PAPER_DESIGN",
    "Axis",
    "ExperimentDesign",
    "classify",
    "classify_pair",
    "design_from_dict",
    "is_paper",
    "load_design",
    "pair_column",
]
