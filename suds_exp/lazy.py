"""Packages whose public names load on first use (PEP 562).

A package's ``__init__`` names where each public name lives; `exports` gives it the
module ``__getattr__`` and ``__dir__`` that import that home the first time the name is
asked for. So `suds-exp status` or `trials` import the one module they use, not every
module a package re-exports (learners, pandas, SQLAlchemy).
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Iterable, Mapping


def exports(
    package: str, homes: Mapping[str, str], public: Iterable[str]
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package``: each name of ``homes`` (name -> module)
    is imported from its module on first use and kept in the package."""
    public = list(public)

    def __getattr__(name: str):
        home = homes.get(name)
        if home is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(home), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(public))

    return __getattr__, __dir__
