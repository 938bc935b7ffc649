"""Every named learner, once: its name, family, whether it uses SUDS, its tags and the
class that builds it.

The one home of learner names ("one home per fact"): the paper's five
(`LEARNERS`), the survey's set (`SURVEY_LEARNERS`), the online learners and the
scikit-learn baselines are read from `REGISTRY`, and so are the roles other modules give
a learner (`PHASE_ONLY`, `TLS`, ... below). `suds_exp.models` builds its model lists
(`MODELS`, `ONLINE_MODELS`, ...) from each entry's `builder`; the store writes the SQL
vocabulary table ``learners`` (created by migration 019) from `REGISTRY` each time it
brings a database up to date (`suds_exp.store.migrate`), so a new learner needs no
migration.

This module is plain data and imports nothing, so any module may read it, the store
included (it sits at the bottom of the house). ``suds_exp.models.registry`` is the same
module under the name the models box has always used.
"""

from __future__ import annotations

from dataclasses import dataclass

#: The suffix of a learner that also sees the passive shape (SUDS): ``GMR+SUDS``.
SUDS_SUFFIX = "+SUDS"
#: The suffix of a learner with a momentum state: ``GMR+P``, ``GMR+SUDS+P``.
MOMENTUM_SUFFIX = "+P"
#: The suffix of a learner whose map is not linear in the shape velocity: ``GMR+F``,
#: ``TLS+F``.
FINSLER_SUFFIX = "+F"
#: Tags: the paper's five; ``models="survey"`` of a campaign; ``partial_fit``; the
#: scikit-learn baselines of `baselines.BASELINES`.
TAGS = ("paper", "survey", "online", "baseline")


@dataclass(frozen=True)
class LearnerInfo:
    """One learner: ``name`` as `make_model` takes it and ``results.model`` stores it,
    ``family`` (the learner without SUDS), ``suds`` (it uses the passive shape),
    ``tags`` (a subset of `TAGS`) and ``builder``, the class `make_model` builds it with:
    ``"module.Class"`` inside `suds_exp.models`, or ``"package.module:Class"`` elsewhere
    (a scikit-learn baseline is built by ``sklearn_adapter.SklearnLearner`` from its
    recipe in `baselines.BASELINES`)."""

    name: str
    family: str
    suds: bool
    tags: frozenset[str]
    builder: str


#: The builder of every scikit-learn baseline (its recipe: `baselines.BASELINES[family]`).
ADAPTER = "sklearn_adapter.SklearnLearner"


def _learner(
    family: str, suds: bool, builder: str, *tags: str, name: str | None = None
) -> LearnerInfo:
    name = name or family + (SUDS_SUFFIX if suds else "")
    return LearnerInfo(name, family, suds, frozenset(tags), builder)


#: The multi-layer perceptron the paper's Future Work compares with GMR (the survey's
#: default learner to compare).
MLP = "MLP"
#: All named learners, in display order (the paper's five in its order first).
REGISTRY: tuple[LearnerInfo, ...] = (
    _learner("phase-only", False, "phase_only.PhaseOnly", "paper", "survey"),
    _learner("TLS", False, "tls.TLS", "paper", "survey"),
    _learner("TLS", True, "tls.TLSSuds", "paper", "survey"),
    _learner("GMR", False, "gmr.GMR", "paper", "survey"),
    _learner("GMR", True, "gmr.GMRSuds", "paper", "survey"),
    _learner(MLP, False, ADAPTER, "baseline", "survey"),
    _learner(MLP, True, ADAPTER, "baseline", "survey"),
    _learner("GBT", False, ADAPTER, "baseline", "survey"),
    _learner("GBT", True, ADAPTER, "baseline"),
    _learner("kNN", False, ADAPTER, "baseline", "survey"),
    _learner("kNN", True, ADAPTER, "baseline"),
    _learner("KRR", False, ADAPTER, "baseline", "survey"),
    _learner("KRR", True, ADAPTER, "baseline"),
    _learner("GMR", False, "online.OnlineGMR", "online", name="OnlineGMR"),
    _learner("GMR", True, "online.OnlineGMRSuds", "online", name="OnlineGMR+SUDS"),
    _learner("GMR", True, "gradual.GradualGMRSuds", "online", name="GradualGMR+SUDS"),
    # the paper's Future Work: a low-dimensional momentum state (models/momentum.py)
    _learner("GMR", False, "momentum.GMRMomentum", name="GMR" + MOMENTUM_SUFFIX),
    _learner("GMR", True, "momentum.GMRSudsMomentum", name="GMR" + SUDS_SUFFIX + MOMENTUM_SUFFIX),
    # and a map homogeneous but not linear in the shape velocity (models/finsler.py)
    _learner("GMR", False, "finsler.GMRFinsler", name="GMR" + FINSLER_SUFFIX),
    _learner("TLS", False, "tls_finsler.TLSFinsler", name="TLS" + FINSLER_SUFFIX),
)
BY_NAME = {info.name: info for info in REGISTRY}


def learner(name: str) -> LearnerInfo | None:
    """The registry's entry for ``name``, or None. Reads `REGISTRY` when called, so a
    learner registered later (a test's toy learner) is found too."""
    return next((info for info in REGISTRY if info.name == name), None)


def tagged(tag: str) -> tuple[str, ...]:
    """Names of the learners tagged ``tag`` (one of `TAGS`), in `REGISTRY` order."""
    if tag not in TAGS:
        raise ValueError(f"tag {tag!r}: expected one of {', '.join(TAGS)}")
    return tuple(info.name for info in REGISTRY if tag in info.tags)


#: The paper's learners, in its order (`suds_exp.models.make_model` builds each).
LEARNERS = tagged("paper")
#: ``models="survey"``: the paper's five and the survey's scikit-learn baselines.
SURVEY_LEARNERS = tagged("survey")
#: Learners with `partial_fit(samples)`.
ONLINE_LEARNERS = tagged("online")
#: The named scikit-learn baselines, each with and without SUDS.
BASELINE_LEARNERS = tagged("baseline")
#: Learners with a momentum state (`models.momentum`): untagged, in `REGISTRY` order.
MOMENTUM_LEARNERS = tuple(i.name for i in REGISTRY if i.name.endswith(MOMENTUM_SUFFIX))
#: Learners whose map is homogeneous but not linear in the shape velocity.
FINSLER_LEARNERS = tuple(i.name for i in REGISTRY if i.name.endswith(FINSLER_SUFFIX))
#: The paper's five by role, for code that compares them (findings, synthetic results).
PHASE_ONLY, TLS, TLS_SUDS, GMR, GMR_SUDS = LEARNERS
