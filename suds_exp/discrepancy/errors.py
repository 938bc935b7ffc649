"""Errors of the discrepancy workflow."""

from suds_exp.errors import SudsError


class DiscrepancyError(SudsError):
    """The discrepancy workflow cannot run as asked (options, trials, versions)."""
