"""suds-exp: learn the motility map of an under-actuated robot from motion capture."""

__version__ = "0.1.0"
