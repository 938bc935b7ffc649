"""How the library's objects show themselves at a prompt and in a notebook.

A class that mixes in `Summary` says what matters about one of its objects in
``_summary() -> (title, [(label, value), ...])``; `Summary` turns that into a one-line
``repr`` and a small HTML table (``_repr_html_``, which Jupyter shows). One place, so that
a `Store`, a `Version`, a learner and a campaign's run all look alike.
"""

from __future__ import annotations

import html
from typing import Any

Fields = list[tuple[str, Any]]


def _text(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, dict):
        return ", ".join(f"{k}={_text(v)}" for k, v in value.items()) or "-"
    return str(value)


def summary_text(title: str, fields: Fields) -> str:
    """``<title: label value, label value>`` on one line."""
    inner = "; ".join(f"{label} {_text(value)}" for label, value in fields)
    return f"<{title}: {inner}>" if inner else f"<{title}>"


def summary_html(title: str, fields: Fields) -> str:
    """An HTML table with the title as its caption, a row a field (text escaped)."""
    rows = "".join(
        f'<tr><th style="text-align:left">{html.escape(label)}</th>'
        f'<td style="text-align:left">{html.escape(_text(value))}</td></tr>'
        for label, value in fields
    )
    return (
        f'<table class="suds-summary"><caption style="text-align:left">'
        f"<strong>{html.escape(title)}</strong></caption>{rows}</table>"
    )


class Summary:
    """A mixin: ``repr`` and ``_repr_html_`` from the class's `_summary`."""

    def _summary(self) -> tuple[str, Fields]:
        raise NotImplementedError

    def __repr__(self) -> str:
        return summary_text(*self._summary())

    def _repr_html_(self) -> str:
        return summary_html(*self._summary())
