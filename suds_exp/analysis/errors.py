"""Errors a user can cause when asking for an analysis or a report."""

from suds_exp.errors import SudsError


class AnalysisError(SudsError):
    """A campaign, option or table cannot be analysed as asked."""
