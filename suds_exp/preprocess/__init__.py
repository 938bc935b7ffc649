"""Preprocessing: markers -> samples (cleaning, body frame, shape, PCA, Phaser, rates),
stored as named, versioned parameter sets."""

from suds_exp.errors import PreprocessError
from suds_exp.preprocess.params import (
    DEFAULTS,
    PRESETS,
    preset_params,
    resolve_params,
)
from suds_exp.preprocess.phaser import Phaser
from suds_exp.preprocess.pipeline import preprocess
from suds_exp.preprocess.rates import Differentiator
from suds_exp.preprocess.version import (
    PrepResult,
    Version,
    get_version,
    list_versions,
    load_samples,
)
from suds_exp.robot import sample_columns

__all__ = [
    "DEFAULTS",
    "Differentiator",
    "PRESETS",
    "Phaser",
    "PrepResult",
    "PreprocessError",
    "Version",
    "get_version",
    "list_versions",
    "load_samples",
    "preprocess",
    "preset_params",
    "resolve_params",
    "sample_columns",
]
