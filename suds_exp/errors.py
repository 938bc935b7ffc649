"""The project's own error types.

Every error a user can cause (bad file, bad option, bad manifest) is raised as a
`SudsError` subclass whose message is one line naming the file/row/option and what was
expected; the CLI prints it and exits with its ``exit_code`` (2, or 3 for a lost
cluster) without a traceback.
"""


class SudsError(Exception):
    """Base class of every user-facing error in suds-exp.

    ``param`` names the Python parameter(s) the error is about (one name or a tuple), as
    the message writes them; the CLI shows each one's flag instead (``trials`` ->
    ``--trials``). ``step`` names the library step that would help (``"ingest"``,
    ``"preprocess"``, ``"init"``, ``"run"``, ``"stream"``, ``"trials"``), which the
    message advises in words; the CLI adds the command that takes it.
    """

    def __init__(
        self,
        message: str = "",
        *,
        param: str | tuple[str, ...] | None = None,
        step: str | tuple[str, ...] | None = None,
    ):
        super().__init__(message)
        self.param = param
        self.step = step

    #: The command line's exit status for this error.
    exit_code = 2


class IngestError(SudsError):
    """A capture file, manifest or marker layout cannot be ingested as given."""


class StoreError(SudsError):
    """The database cannot be opened, migrated or queried as asked."""


class ConfigError(SudsError):
    """A configuration file, option or parameter has an invalid value."""


class PreprocessError(SudsError):
    """A trial cannot be preprocessed (gap too long, marker missing) or a version is unknown."""


class ModelError(SudsError):
    """A samples frame cannot be used by a learner as given (missing column, too few rows)."""


class CampaignError(SudsError):
    """A campaign cannot be created, continued or run as asked."""


class ClusterLostError(CampaignError):
    """The dask cluster went away during a run (scheduler killed, network gone): what was
    finished is stored and the same command resumes. Exit status 3, so a script can tell
    it from a refused input."""

    exit_code = 3


class AnalysisError(SudsError):
    """A campaign, option or table cannot be analysed as asked."""


class DiscrepancyError(SudsError):
    """The discrepancy workflow cannot run as asked (options, trials, versions)."""


class StreamError(SudsError):
    """A stream cannot run as asked (bad option, definition differs from the stored one)."""


class BodyError(SudsError):
    """A body description that cannot be used."""
