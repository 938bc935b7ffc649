"""Marker layout: which of a capture's markers plays each of the robot's 11 roles.

A layout file is a CSV with columns ``role,marker``. The default layout is the
simulator's: every role's marker carries the role's own name.
"""

from __future__ import annotations

import json
from pathlib import Path

from suds_exp.errors import IngestError
from suds_exp.ingest.tables_csv import read_text_table
from suds_exp.robot import ROLES  # the robot's marker roles (also imported from here)

DEFAULT_LAYOUT = {role: role for role in ROLES}


def read_layout(path: Path) -> dict[str, str]:
    """Role -> marker name from the layout CSV at ``path``; every role must be given."""
    path = Path(path)
    table = read_text_table(path, "marker layout", ("role", "marker"))
    layout: dict[str, str] = {}
    for i, (role, marker) in enumerate(zip(table.role, table.marker, strict=True), start=2):
        role, marker = role.strip(), marker.strip()
        if role not in ROLES:
            raise IngestError(
                f"{path}: line {i}: unknown role {role!r}; expected one of {', '.join(ROLES)}"
            )
        if role in layout:
            raise IngestError(f"{path}: line {i}: role {role!r} is given twice")
        layout[role] = marker
    lacking = [r for r in ROLES if r not in layout]
    if lacking:
        raise IngestError(f"{path}: layout lacks role(s) {', '.join(lacking)}")
    return layout


def check_layout(
    layout: dict[str, str], marker_names: list[str], source: str, capture: Path
) -> None:
    """Raise unless every marker the layout names is in ``marker_names``."""
    have = set(marker_names)
    for role, marker in layout.items():
        if marker not in have:
            raise IngestError(
                f"{source}: names marker {marker!r} (role {role}), which {capture} lacks; "
                f"its markers are {', '.join(marker_names)}"
            )


def layout_json(layout: dict[str, str] | None) -> str | None:
    """The layout as stored in ``trials.layout`` (None for the default names)."""
    if layout is None or layout == DEFAULT_LAYOUT:
        return None
    return json.dumps(layout, sort_keys=True)


def trial_layout(stored: str | None) -> dict[str, str]:
    """Role -> marker name of a trial, from its ``trials.layout`` value."""
    return json.loads(stored) if stored else dict(DEFAULT_LAYOUT)
