"""What shapes a discrepancy run: its options and their checks (stored with the run)."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field

from suds_exp.discrepancy.discover import DiscoverySettings
from suds_exp.discrepancy.effects import effect_names
from suds_exp.discrepancy.fit_candidates import FitSettings
from suds_exp.discrepancy.replay import ReplaySettings
from suds_exp.errors import DiscrepancyError


@dataclass
class DiscrepancyOptions:
    """Everything that shapes a run (stored with it).

    Parameters
    ----------
    alpha : float
        Level of the paired test naming an effect (the candidates tested in the order
        of their training loss until one fails, `adjust_in_training_order`).
    max_effects : int
        Stop after naming this many effects.
    seed : int
        Seed of the trial split and the bootstraps.
    replay : ReplaySettings, optional
        Window cutting; None: defaults with the preprocessing version's differentiator.
    fit : FitSettings
    refine : bool
        Re-fit the accepted candidate's parameter at the capture rate (no decimation), so
        its value and interval are not biased by the replay's discretisation.
    passive : bool
        Compare the passive shape r_p too (when the preprocessing version has one); the
        loss then weighs body velocity and passive shape half and half. On by default:
        it is what makes `flippers` and `spoke_oscillation` (markers only) visible.
    gap_floor : float
        Held-out loss (mean squared residual over each channel's mean square, so 0.01 is
        a residual of about 10% of the signal) below which a remaining gap is called
        negligible even when it is statistically systematic.
    exclude : tuple of str
        Effects never offered as candidates: the withheld-effect
        checks hide an effect in the data and exclude it here.
    discover : bool
        When no candidate is significant and a systematic gap above ``gap_floor``
        remains, fit a sparse learned correction (`discover.py`) on the training trials
        and add it if it passes its own held-out test at ``alpha``.
    discovery : DiscoverySettings
    """

    alpha: float = 0.01
    max_effects: int = 3
    seed: int = 0
    replay: ReplaySettings | None = None
    fit: FitSettings = field(default_factory=FitSettings)
    refine: bool = True
    passive: bool = True
    gap_floor: float = 0.01
    exclude: tuple[str, ...] = ()
    discover: bool = True
    discovery: DiscoverySettings = field(default_factory=DiscoverySettings)

    def __post_init__(self) -> None:
        self.exclude = check_exclude(self.exclude)
        if not self.discover and set(effect_names()) <= set(self.exclude):
            raise DiscrepancyError(
                "exclude: every candidate is excluded and discovery is off; "
                "nothing could explain the gap",
                param="exclude",
            )

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


def check_exclude(names: Sequence[str]) -> tuple[str, ...]:
    """``names`` of effects never offered as candidates, each checked, as a tuple."""
    known = effect_names()
    if isinstance(names, str):
        names = (names,)
    out = tuple(str(x).strip() for x in names if str(x).strip())
    for x in out:
        if x not in known:
            raise DiscrepancyError(
                f"exclude {x!r}: unknown effect; expected one of {', '.join(known)}",
                param="exclude",
            )
    return out


def check_options(opts: DiscrepancyOptions) -> None:
    """Raise `DiscrepancyError` for an ``alpha`` outside (0, 1) or a negative
    ``max_effects``."""
    if not 0 < opts.alpha < 1:
        raise DiscrepancyError(f"alpha {opts.alpha}: must be between 0 and 1", param="alpha")
    if opts.max_effects < 0:
        raise DiscrepancyError(f"max_effects {opts.max_effects}: must be >= 0", param="max_effects")
