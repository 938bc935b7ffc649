"""The error preprocessing raises for data or versions it cannot use as given."""

from suds_exp.errors import SudsError


class PreprocessError(SudsError):
    """A trial cannot be preprocessed (gap too long, marker missing) or a version is unknown."""
