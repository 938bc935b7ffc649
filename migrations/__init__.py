"""The schema migrations (``NNN_name.sql``), shipped as package data of ``suds_exp``.

This folder stays at the top of the repository; pyproject.toml maps it into the wheel as
the package ``suds_exp.migrations`` so that an installed suds-exp finds its SQL with
``importlib.resources`` (suds_exp/store/migrate.py). It holds no code.
"""
