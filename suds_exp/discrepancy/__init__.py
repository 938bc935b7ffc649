"""Discrepancy workflow: replay measured trials through the simulator, localise the gap,
fit and test the simulator's named effects as candidates, name the one that significantly
closes the held-out gap, add it and repeat."""

from suds_exp.discrepancy.discover import Discovery, DiscoverySettings
from suds_exp.discrepancy.effects import Candidate, candidates_for, parse_effect_items
from suds_exp.discrepancy.fit_candidates import FitSettings
from suds_exp.discrepancy.options import DiscrepancyOptions, check_exclude
from suds_exp.discrepancy.replay import ReplaySettings
from suds_exp.discrepancy.result import DiscrepancyResult
from suds_exp.discrepancy.workflow import run_discrepancy
from suds_exp.errors import DiscrepancyError

__all__ = [
    "Candidate",
    "DiscrepancyError",
    "DiscrepancyOptions",
    "DiscrepancyResult",
    "Discovery",
    "DiscoverySettings",
    "FitSettings",
    "ReplaySettings",
    "candidates_for",
    "check_exclude",
    "parse_effect_items",
    "run_discrepancy",
]
