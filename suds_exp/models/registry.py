"""The learner registry under the name the models box reads it by: `suds_exp.vocabulary`.

The registry lives at the bottom of the house so that the store can write the SQL table
``learners`` from it; this module only re-exports its names.
"""

from suds_exp.vocabulary import (
    ADAPTER,
    BASELINE_LEARNERS,
    BY_NAME,
    FINSLER_LEARNERS,
    FINSLER_SUFFIX,
    GMR,
    GMR_SUDS,
    LEARNERS,
    MLP,
    MOMENTUM_LEARNERS,
    MOMENTUM_SUFFIX,
    ONLINE_LEARNERS,
    PHASE_ONLY,
    REGISTRY,
    SUDS_SUFFIX,
    SURVEY_LEARNERS,
    TAGS,
    TLS,
    TLS_SUDS,
    LearnerInfo,
    tagged,
)

__all__ = [
    "ADAPTER",
    "BASELINE_LEARNERS",
    "BY_NAME",
    "FINSLER_LEARNERS",
    "FINSLER_SUFFIX",
    "GMR",
    "GMR_SUDS",
    "LEARNERS",
    "MLP",
    "MOMENTUM_LEARNERS",
    "MOMENTUM_SUFFIX",
    "ONLINE_LEARNERS",
    "PHASE_ONLY",
    "REGISTRY",
    "SUDS_SUFFIX",
    "SURVEY_LEARNERS",
    "TAGS",
    "TLS",
    "TLS_SUDS",
    "LearnerInfo",
    "tagged",
]
