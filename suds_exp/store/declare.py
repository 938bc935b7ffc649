"""Declare a SQLAlchemy Core table from a short column list, one column a line.

Each box's ``tables.py`` mirrors the schema that ``migrations/*.sql`` creates, so that
queries are built with parameters instead of string formatting. A column is written as
``name Type [key] [required] [unique]``: `Type` is a SQLAlchemy type's name (``String``,
``Integer``, ``Float``, ``Boolean``, ``DateTime``; ``Float[]`` an array of it), ``key``
sets ``primary_key=True``, ``required`` sets ``nullable=False`` and ``unique`` sets
``unique=True``. One parser serves the four ``tables.py`` modules instead of one
``sa.Column(...)`` call per column in each.
"""

from __future__ import annotations

import sqlalchemy as sa

_TYPES = {t.__name__: t for t in (sa.String, sa.Integer, sa.Float, sa.Boolean, sa.DateTime)}

# each flag word, and the sa.Column keyword and value it stands for
_FLAGS = {"key": ("primary_key", True), "required": ("nullable", False), "unique": ("unique", True)}


def _column_type(word: str):
    """The SQLAlchemy type named `word`; ``Float[]`` is ``sa.ARRAY(sa.Float)``."""
    if word.endswith("[]"):
        return sa.ARRAY(_TYPES[word[:-2]])
    return _TYPES[word]


def _column(line: str) -> sa.Column:
    """One ``sa.Column`` from ``"name Type [key] [required] [unique]"``."""
    name, type_word, *flags = line.split()
    unknown = set(flags) - set(_FLAGS)
    if type_word.removesuffix("[]") not in _TYPES or unknown:
        raise ValueError(f"column {name!r}: cannot read {line.strip()!r}")
    return sa.Column(name, _column_type(type_word), **dict(_FLAGS[f] for f in flags))


def columns(lines: str) -> list[sa.Column]:
    """The columns of `lines`, one column a line, in the order written."""
    return [_column(line) for line in lines.splitlines() if line.strip()]


def declare_table(name: str, metadata: sa.MetaData, lines: str, *extra: sa.SchemaItem) -> sa.Table:
    """The table `name` with the columns of `lines`, then the `extra` items.

    `extra` takes further columns (ones built in a loop) and table constraints
    (``sa.UniqueConstraint``), appended after the written columns.
    """
    return sa.Table(name, metadata, *columns(lines), *extra)
