"""suds-exp: learn the motility map of an under-actuated robot from motion capture."""

from importlib.metadata import PackageNotFoundError, version

try:
    # one source of truth: the version in pyproject.toml, as installed
    __version__ = version("suds-exp")
except PackageNotFoundError:  # imported from a source tree that was never installed
    __version__ = "0+unknown"
