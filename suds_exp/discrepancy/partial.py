"""Cause or partial explanation? The check every named effect passes after it is added.

A library candidate can be significant without being the missing physics: when the real
effect is not in the library, the nearest candidate often mimics part of it (a constant
drag scale mimics a drag that grows with distance travelled). Such a candidate is
recognised by its strength not being constant: the data want it stronger in some parts
and weaker in others. After an effect is added, the next replay gives its contribution
D (replay with it minus replay without it, no extra replay) and
`discover.effect_constancy` tests on held-out trials whether letting D vary with
distance, time, a segment's sliding direction or the condition (gait and frequency)
removes a material part of what remains. A second sign is a fit pinned at the edge of
the effect's realistic range: the data want more of it than the physics allows, so at
any realistic strength it does not explain the gap. In either case the effect is kept
in the model but reported as a *partial* explanation (step decision ``partial``), the
remaining gap counts as unexplained by the library, and the learned correction is fitted
to it with D and its variations among the features, so the report says how much each
part closed.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from suds_exp.discrepancy.discover import Discovery, Gap, discover, effect_constancy
from suds_exp.discrepancy.features import channel_features, effect_features, feature_library
from suds_exp.discrepancy.replay import WindowSet


def check_named(
    step,
    sim_before: np.ndarray,
    sim_after: np.ndarray,
    full: WindowSet,
    samples: pd.DataFrame,
    meas: np.ndarray,
    scales: np.ndarray,
    train_ids,
    opts,
    half_middle_mm: float,
) -> list[tuple[np.ndarray, list]]:
    """Test the effect ``step`` accepted; set ``step.constancy`` and, when its strength
    is not constant or its fit is pinned at the edge of its realistic range
    (`CandidateResult.at_range_edge`), ``step.decision = "partial"``.

    ``sim_before`` / ``sim_after``: the full-rate replays (n_windows, n_samples,
    n_channels) without and with the effect; ``half_middle_mm``: the model's half middle
    segment, mm (for each segment's sliding direction). Returns ``[(Xe, features)]`` for
    the learned correction when the effect is partial, else ``[]``: D and its variations
    along distance, time and sliding direction, which are forms of physics; the
    per-condition scales test the form but name no mechanism, so they stay out of it.
    """
    label = step.accepted.candidate.label
    Xe, feats = effect_features(
        full, samples, sim_after, sim_after - sim_before, label, half_middle_mm
    )
    gap = Gap(sim_after, meas, scales, full.trial_id, train_ids)
    step.constancy = effect_constancy(Xe, feats, gap, opts.alpha, opts.fit.min_improvement, label)
    step.constancy.at_range_edge = step.accepted.at_range_edge
    if not (step.constancy.significant or step.constancy.at_range_edge):
        return []
    step.decision = "partial"
    physical = [i for i, f in enumerate(feats) if f.family != "condition"]
    return [(Xe[..., physical], [feats[i] for i in physical])]


def discover_step(
    full: WindowSet,
    samples: pd.DataFrame,
    sim: np.ndarray,
    meas: np.ndarray,
    scales: np.ndarray,
    train_ids,
    opts,
    rng: np.random.Generator,
    half_middle_mm: float,
    partial: list[tuple[np.ndarray, list]] = (),
) -> Discovery:
    """The learned correction of the current replay ``sim`` (no new replay): the shared
    `feature_library`, each channel's own lag (`channel_features`) and, for every effect
    found partial, its contribution and its variations (`effect_features`).
    ``half_middle_mm``: the model's half middle segment, mm."""
    X, feats = feature_library(full, samples, sim, half_middle_mm)
    blocks = [channel_features(full, sim)] + list(partial)
    Xc = np.concatenate([b[0] for b in blocks], axis=-1)
    cfeats = [f for b in blocks for f in b[1]]
    return discover(
        X,
        feats,
        Gap(sim, meas, scales, full.trial_id, train_ids),
        full.channels,
        opts.alpha,
        opts.fit.min_improvement,
        opts.discovery,
        rng,
        Xc,
        cfeats,
    )
