"""Stored definitions: what a campaign or stream was created with, and the refusal of a
continuation that differs from it.

A named campaign or stream stores its definition (a JSON document) when it is created;
continuing it recomputes the definition from the options given and refuses to go on when
anything differs, naming each difference, since the stored rows would no longer describe
the same experiment.
"""

from __future__ import annotations

import json

from suds_exp.errors import SudsError

#: Differences named in a refusal before "and N more".
SHOWN = 6


def differences(stored: dict, new: dict, prefix: str = "") -> list[str]:
    """Human-readable ``path: old -> new`` lines for every leaf where the two differ."""
    out: list[str] = []
    for key in sorted(set(stored) | set(new), key=str):
        path = f"{prefix}{key}"
        a, b = stored.get(key, "<absent>"), new.get(key, "<absent>")
        if isinstance(a, dict) and isinstance(b, dict):
            out += differences(a, b, path + ".")
        elif a != b:
            out.append(f"{path}: {_short(a)} -> {_short(b)}")
    return out


def _short(value) -> str:
    text = json.dumps(value, default=str)
    return text if len(text) <= 60 else text[:57] + "..."


def check_same(
    stored: dict, new: dict, what: str, advice: str, error: type[SudsError] = SudsError
) -> None:
    """Raise ``error`` naming up to `SHOWN` differences when ``new`` differs from the
    ``stored`` definition of ``what`` ("campaign 'paper'"); ``advice`` ends the line."""
    diff = differences(stored, new)
    if diff:
        raise error(
            f"{what} exists with a different definition ("
            + "; ".join(diff[:SHOWN])
            + (f"; and {len(diff) - SHOWN} more" if len(diff) > SHOWN else "")
            + f"); {advice}"
        )
