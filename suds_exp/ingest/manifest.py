"""Manifest CSV: which gait, frequency and repeat each capture file is.

Columns ``file,gait,frequency_hz,repeat,notes``; ``file`` is relative to the
manifest's folder (or absolute); ``frequency_hz`` may be a decimal or a fraction
(``1/3``); ``notes`` may be empty.

With an experiment description (`suds_exp.experiment`, ``design=``) other than the
paper's, the columns are ``file,frequency_hz,repeat,notes`` and one per declared axis
(``gait`` is then whatever the design declares, or absent): a column the design does not
declare is refused naming the file and column, and each cell is checked against its axis.
The trial's ``gait`` is then its condition label (`ExperimentDesign.label`) and its axis
values go to `trial_conditions` (migration 020).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from suds_exp.errors import ConfigError, IngestError
from suds_exp.experiment import FREQUENCY_AXIS, Axis, ExperimentDesign, is_paper
from suds_exp.ingest.experiment import levels_json, store_description, store_values
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
    #: (axis, value) of every declared axis of a user design; empty for the paper's
    axes: tuple[tuple[str, str | float], ...] = ()


def read_manifest(path: Path, design: ExperimentDesign | None = None) -> dict[Path, Condition]:
    """Resolved file path -> `Condition` for every row of the manifest at ``path``;
    ``design``: the experiment's axes (None or the paper's: gait and frequency_hz)."""
    path = Path(path)
    if not is_paper(design):
        return _read_designed(path, design)
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
                "or a gait file's name (.csv, .toml); declare your own gaits in a TOML "
                "description given as experiment (docs/how-to/own-experiment.md)",
                param="experiment",
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


#: The gait's cycle frequency when the design does not declare it an axis.
_CYCLE_RATE = Axis(FREQUENCY_AXIS, "numeric")


def _read_designed(path: Path, design: ExperimentDesign) -> dict[Path, Condition]:
    required = ("file", FREQUENCY_AXIS, "repeat", *design.names)
    table = read_text_table(path, "manifest", tuple(dict.fromkeys(required)))
    known = {*required, "notes"}
    unknown = [c for c in table.columns if c not in known]
    if unknown:
        raise IngestError(
            f"{path}: line 1: column {unknown[0]!r} is not an axis of the experiment "
            f"({design.source}: {', '.join(design.names) or 'no axes'})",
            param="experiment",
        )
    frequency = design.axis(FREQUENCY_AXIS) if FREQUENCY_AXIS in design.names else None
    out: dict[Path, Condition] = {}
    for i, row in enumerate(table.to_dict("records"), start=2):
        where = f"{path}: line {i}"
        file = (path.parent / row["file"].strip()).resolve()
        if not file.is_file():
            raise IngestError(f"{where}: file {row['file'].strip()!r} does not exist")
        try:
            values = {a.name: a.parse(row[a.name], where) for a in design.axes}
            hz = (frequency or _CYCLE_RATE).parse(row[FREQUENCY_AXIS], where)
        except ConfigError as exc:
            raise IngestError(str(exc), param="manifest") from None
        try:
            repeat = int(row["repeat"].strip())
        except ValueError:
            raise IngestError(
                f"{where}: repeat {row['repeat']!r}: expected a whole number"
            ) from None
        if file in out:
            raise IngestError(f"{where}: file {row['file'].strip()!r} is listed twice")
        notes = row.get("notes", "").strip() or None
        out[file] = Condition(design.label(values), hz, repeat, notes, tuple(values.items()))
    return out


def check_axes(conn, design: ExperimentDesign) -> None:
    """Refuse a design whose axes differ from those already stored (`experiment_axes`),
    naming the axis; reads only."""
    stored = {
        r[0]: (r[1], r[2])
        for r in conn.exec_driver_sql("SELECT axis, kind, levels FROM experiment_axes")
    }
    for a in design.axes:
        if a.name in stored and stored[a.name] != (a.kind, levels_json(a)):
            kind, levels = stored[a.name]
            raise IngestError(
                f"{design.source}: axis {a.name!r} is declared {a.kind} {list(a.levels)} but "
                f"the database has it {kind} {levels or ''}; use the same declaration",
                param="experiment",
            )


def store_condition(conn, trial_id: int, condition: Condition, design: ExperimentDesign) -> None:
    """Store the design as the database's description (`store_description`: the axes not
    stored yet) and the trial's values along its axes, in the caller's transaction."""
    store_description(conn, design)
    store_values(conn, trial_id, condition.axes)
