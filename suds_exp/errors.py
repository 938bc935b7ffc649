"""The project's own error types.

Every error a user can cause (bad file, bad option, bad manifest) is raised as a
`SudsError` subclass whose message is one line naming the file/row/option and what was
expected; the CLI prints it and exits with status 2 without a traceback.
"""


class SudsError(Exception):
    """Base class of every user-facing error in suds-exp."""


class IngestError(SudsError):
    """A capture file, manifest or marker layout cannot be ingested as given."""


class StoreError(SudsError):
    """The database cannot be opened, migrated or queried as asked."""


class ConfigError(SudsError):
    """A configuration file, option or parameter has an invalid value."""
