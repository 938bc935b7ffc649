"""What a discrepancy run found: its steps, its outcome, and their plain-data form."""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.discrepancy.discover import Constancy, Discovery
from suds_exp.discrepancy.fit_candidates import CandidateResult
from suds_exp.preprocess.rates import Differentiator
from suds_exp.sim.config import SimConfig


@dataclass
class Step:
    """One pass of the loop: the model replayed, its gap, the candidates, the decision."""

    index: int
    model: SimConfig
    test_loss: float
    test_rmse: np.ndarray
    test_trial_loss: np.ndarray
    localisation: pd.DataFrame
    candidates: list[CandidateResult] = field(default_factory=list)
    unobservable: list[str] = field(default_factory=list)
    accepted: CandidateResult | None = None
    decision: str = "none_significant"
    gap_closed: float | None = None
    systematic: tuple[float, float] = (float("nan"), 1.0)
    correlations: pd.DataFrame | None = None
    example: dict | None = None
    discovery: Discovery | None = None
    constancy: Constancy | None = None  # the accepted effect's check (`partial.py`)


@dataclass
class DiscrepancyResult:
    """Outcome of a run. ``named`` lists the accepted effects in order; ``differentiator``
    is the one the replay's rates went through (the preprocessing version's own)."""

    run_id: int | None
    name: str
    prep_version: str | None
    steps: list[Step]
    train_trials: list[int]
    test_trials: list[int]
    start_model: SimConfig
    final_model: SimConfig
    outcome: str
    seconds: float
    cpu_seconds: float = 0.0
    report_dir: Path | None = None
    differentiator: Differentiator | None = None

    @property
    def named(self) -> list[dict]:
        out = []
        for s in self.steps:
            a = s.accepted
            if a is None:
                continue
            out.append(
                {
                    "step": s.index,
                    "effect": a.candidate.effect,
                    "candidate": a.candidate.label,
                    "parameter": a.candidate.param,
                    "value": a.value,
                    "ci": list(a.ci) if a.ci is not None else None,
                    "unit": a.candidate.unit,
                    "p_adjusted": a.p_adjusted,
                    "gap_before": s.test_loss,
                    "gap_after": self.steps[s.index + 1].test_loss
                    if s.index + 1 < len(self.steps)
                    else None,
                    "gap_closed": s.gap_closed,
                    # "partial": its strength is not constant (`partial.py`), not the cause
                    "role": "partial" if s.decision == "partial" else "cause",
                }
            )
        return out

    @property
    def gap_before(self) -> float:
        """Held-out loss of the starting model (mean normalised squared residual)."""
        return self.steps[0].test_loss

    @property
    def gap_after(self) -> float:
        """Held-out loss of the final model."""
        return self.steps[-1].test_loss

    @property
    def discovery(self) -> Discovery | None:
        """The sparse correction fitted at the last step (None when none was tried)."""
        return self.steps[-1].discovery

    @property
    def gap_after_correction(self) -> float:
        """Held-out loss of the final model with the learned correction when it was
        added (significant), else `gap_after`."""
        d = self.discovery
        return float(np.mean(d.test_after)) if d is not None and d.significant else self.gap_after

    def to_dict(self) -> dict:
        """The run as plain data (JSON-ready), as every result object of the package gives it."""
        last = self.steps[-1]
        return {
            "run_id": self.run_id,
            "name": self.name,
            "prep_version": self.prep_version,
            "differentiator": dataclasses.asdict(self.differentiator)
            if self.differentiator is not None
            else None,
            "named": self.named,
            "gap_before": self.gap_before,
            "gap_after": self.gap_after,
            "rmse_vx_before": float(self.steps[0].test_rmse[0]),
            "rmse_vx_after": float(last.test_rmse[0]),
            "steps": [
                {
                    "step": s.index,
                    "test_loss": s.test_loss,
                    "test_rmse": dict(
                        zip(("vx", "vy", "wz"), map(float, s.test_rmse), strict=True)
                    ),
                    "decision": s.decision,
                    "accepted": s.accepted.candidate.label if s.accepted else None,
                    "candidates": [
                        {
                            "candidate": r.candidate.label,
                            "value": r.value,
                            "ci": list(r.ci) if r.ci else None,
                            "improvement": r.improvement,
                            "p_adjusted": r.p_adjusted,
                            "significant": r.significant,
                        }
                        for r in s.candidates
                    ],
                    "unobservable": s.unobservable,
                    "systematic_p": s.systematic[1],
                    "varying_strength_p": s.constancy.p_value if s.constancy else None,
                    "varies_with": s.constancy.varies_with if s.constancy else None,
                    "at_range_edge": s.constancy.at_range_edge if s.constancy else None,
                }
                for s in self.steps
            ],
            "discovery": discovery_json(self.discovery),
            "gap_after_correction": self.gap_after_correction,
            "outcome": self.outcome,
            "seconds": self.seconds,
            "cpu_seconds": self.cpu_seconds,
            "report_dir": str(self.report_dir) if self.report_dir else None,
            "train_trials": self.train_trials,
            "test_trials": self.test_trials,
        }

    def to_json(self) -> dict:
        """Deprecated spelling of `to_dict` (kept for one release)."""
        warnings.warn(
            "DiscrepancyResult.to_json() is deprecated; use to_dict()",
            DeprecationWarning,
            stacklevel=2,
        )
        return self.to_dict()


def discovery_json(d: Discovery | None) -> dict | None:
    """The learned correction as plain data (None when none was tried)."""
    if d is None:
        return None
    return {
        "significant": d.significant,
        "p_value": d.p_value,
        "gap_before": float(np.mean(d.test_before)),
        "gap_after": float(np.mean(d.test_after)),
        "gap_closed": d.improvement,
        "physics": d.physics,
        "physics_by_part": d.physics_by_part,
        "leading": d.leading,
        "equations": d.equations(),
        "terms": [
            {
                "channel": t.channel,
                "feature": t.feature.name,
                "family": t.feature.family,
                "coef": t.coef,
                "ci": list(t.ci),
                "unit": t.unit,
            }
            for t in d.terms
        ],
    }
