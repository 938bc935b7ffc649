"""Manifest CSV: which gait, frequency and repeat each capture file is.

Columns ``file,gait,frequency_hz,repeat,notes``; ``file`` is relative to the
manifest's folder (or absolute); ``frequency_hz`` may be a decimal or a fraction
(``1/3``); ``notes`` may be empty.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from suds_exp.errors import IngestError
from suds_exp.ingest.tables_csv import read_text_table
from suds_exp.robot import GAITS, parse_frequency

COLUMNS = ("file", "gait", "frequency_hz", "repeat", "notes")
GAIT_FILE_SUFFIXES = (".csv", ".toml")


@dataclass(frozen=True)
class Condition:
    """The experimental condition of one capture."""

    gait: str
    frequency_hz: float
    repeat: int
    notes: str | None = None


def read_manifest(path: Path) -> dict[Path, Condition]:
    """Resolved file path -> `Condition` for every row of the manifest at ``path``."""
    path = Path(path)
    table = read_text_table(path, "manifest", COLUMNS[:4])
    out: dict[Path, Condition] = {}
    for i, row in enumerate(table.itertuples(index=False), start=2):
        where = f"{path}: line {i}"
        file = (path.parent / row.file.strip()).resolve()
        if not file.is_file():
            raise IngestError(f"{where}: file {row.file.strip()!r} does not exist")
        gait = row.gait.strip()
        # a gait file's name (`simulate --gait-file`) names the gait it ran
        if gait not in GAITS and not gait.lower().endswith(GAIT_FILE_SUFFIXES):
            raise IngestError(
                f"{where}: unknown gait {gait!r}; expected one of {', '.join(GAITS)} "
                "or a gait file's name (.csv, .toml)"
            )
        try:
            freq = parse_frequency(row.frequency_hz)
        except (ValueError, ZeroDivisionError):
            raise IngestError(
                f"{where}: frequency_hz {row.frequency_hz!r}: expected a positive number of Hz"
            ) from None
        try:
            repeat = int(row.repeat.strip())
        except ValueError:
            raise IngestError(f"{where}: repeat {row.repeat!r}: expected a whole number") from None
        if file in out:
            raise IngestError(f"{where}: file {row.file.strip()!r} is listed twice")
        notes = getattr(row, "notes", "").strip() or None
        out[file] = Condition(gait, freq, repeat, notes)
    return out
