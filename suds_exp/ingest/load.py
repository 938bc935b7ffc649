"""Ingest capture files into the store: one transaction per file."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import sqlalchemy as sa

from suds_exp.errors import IngestError
from suds_exp.experiment import ExperimentDesign, is_paper
from suds_exp.ingest.layout import check_layout, layout_json, read_layout
from suds_exp.ingest.manifest import Condition, check_axes, read_manifest, store_condition
from suds_exp.ingest.pose import PoseOptions
from suds_exp.ingest.readers import READERS, read_capture
from suds_exp.progress import progress_bar
from suds_exp.store import Store
from suds_exp.store.tables import markers, trials


@dataclass(frozen=True)
class IngestResult:
    """What happened to one file: ``status`` is ``"ingested"``, ``"skipped"`` or
    ``"failed"`` (only with ``keep_going``; then ``trial_id`` is None and ``message`` is
    the one-line reason)."""

    path: Path
    status: str
    trial_id: int | None
    n_frames: int
    message: str
    #: the refusal itself (``failed`` only): its ``param`` names what to change
    error: IngestError | None = None


def expand_paths(paths: list[Path], exclude: set[Path]) -> list[Path]:
    """Files as given, and the capture files (by extension) inside given folders."""
    files: list[Path] = []
    for path in paths:
        path = Path(path)
        if path.is_dir():
            found = sorted(
                p for p in path.rglob("*") if p.is_file() and p.suffix.lower() in READERS
            )
            files.extend(p for p in found if p.resolve() not in exclude)
        else:
            files.append(path)
    return files


def _same_condition(condition: Condition):
    return sa.and_(
        trials.c.gait == condition.gait,
        sa.func.round(trials.c.frequency_hz, 6) == round(condition.frequency_hz, 6),
        trials.c.repeat == condition.repeat,
    )


def ingest_file(
    store: Store,
    path: Path,
    condition: Condition | None = None,
    layout: dict[str, str] | None = None,
    layout_source: str = "layout",
    conn: sa.Connection | None = None,
    pose: PoseOptions | None = None,
    design: ExperimentDesign | None = None,
) -> IngestResult:
    """Read, validate and store one capture file in one transaction.

    A file whose content hash is already stored is skipped. Raises `IngestError` (and
    writes nothing) for a bad file, a layout naming markers the file lacks, or a
    condition already taken by a different capture. ``conn``: a connection from
    ``store.writer()`` to reuse (the transaction is still this file's own). ``pose``: how
    to read keypoint files (`suds_exp.ingest.pose.PoseOptions`). ``design``: the
    experiment whose axes ``condition`` carries values of (`read_manifest`).
    """
    capture, digest = read_capture(path, pose)
    if layout is not None:
        check_layout(layout, capture.marker_names, layout_source, path)
    if conn is None:
        with store.writer() as own:
            return ingest_file(store, path, condition, layout, layout_source, own, pose, design)
    with conn.begin():
        existing = conn.execute(
            sa.select(trials.c.id).where(trials.c.content_hash == digest)
        ).scalar_one_or_none()
        if existing is not None:
            return IngestResult(
                path,
                "skipped",
                existing,
                capture.n_frames,
                f"{path}: already ingested as trial {existing} (same content); nothing done",
            )
        if condition is not None:
            _check_condition_free(conn, path, condition)
        trial_id = conn.execute(
            sa.insert(trials)
            .values(
                source_file=str(Path(path).resolve()),
                content_hash=digest,
                format=capture.format,
                gait=condition.gait if condition else None,
                frequency_hz=condition.frequency_hz if condition else None,
                repeat=condition.repeat if condition else None,
                sample_rate_hz=capture.sample_rate_hz,
                n_frames=capture.n_frames,
                marker_names=list(capture.marker_names),
                layout=layout_json(layout),
                ingested_at=sa.func.current_timestamp(),
                notes=condition.notes if condition else None,
            )
            .returning(trials.c.id)
        ).scalar_one()
        store.insert_df(conn, markers.name, capture.long_frame(trial_id))
        if condition is not None and design is not None and not is_paper(design):
            store_condition(conn, trial_id, condition, design)
    label = (
        f"{condition.gait} {condition.frequency_hz:g} Hz #{condition.repeat}"
        if condition
        else "no condition"
    )
    notes = "".join(f"; {note}" for note in capture.meta.get("notes", []))
    return IngestResult(
        path,
        "ingested",
        trial_id,
        capture.n_frames,
        f"{path}: trial {trial_id}, {capture.n_frames} frames, "
        f"{len(capture.marker_names)} markers ({label}){notes}",
    )


def _check_condition_free(conn: sa.Connection, path: Path, condition: Condition) -> None:
    """Refuse ``path`` when its condition (gait, frequency, repeat) is already a trial."""
    clash = conn.execute(
        sa.select(trials.c.id, trials.c.source_file).where(_same_condition(condition))
    ).first()
    if clash is not None:
        raise IngestError(
            f"{path}: condition gait={condition.gait} frequency_hz="
            f"{condition.frequency_hz:g} repeat={condition.repeat} is already trial "
            f"{clash.id} ({clash.source_file}) with different content"
        )


def ingest_paths(
    store: Store,
    paths: list[Path],
    manifest: Path | None = None,
    layout: Path | None = None,
    progress: bool = True,
    keep_going: bool = False,
    pose: PoseOptions | None = None,
    design: ExperimentDesign | None = None,
) -> list[IngestResult]:
    """Ingest capture files and folders, each file in its own transaction.

    The manifest and layout are checked before any file is read.

    Parameters
    ----------
    store : Store
    paths : list of Path
        Capture files (``.tsv`` QTM export, ``.c3d``, ``.csv`` marker, Vicon Nexus or
        Motive export, ``.trc``) or folders to search.
        When empty, the files the manifest lists are ingested.
    manifest : Path, optional
        CSV ``file,gait,frequency_hz,repeat,notes`` assigning conditions; a file with no
        row is ingested with no condition.
    layout : Path, optional
        CSV ``role,marker`` mapping the capture's marker names to the robot's roles.
    progress : bool
        Show a progress bar when there is more than one file.
    keep_going : bool
        Go on past a bad file: its result has status ``"failed"`` and its one-line
        reason, and nothing of it is stored. Without it, the first bad file stops the run
        with an `IngestError`. Either way the files stored before stay stored.
    pose : PoseOptions, optional
        How to read keypoint files (DeepLabCut, SLEAP, Lightning Pose, Anipose): tracker,
        frame rate, mm per pixel, confidence threshold (`suds_exp.ingest.pose`).
    design : ExperimentDesign, optional
        The experiment's condition axes (`suds_exp.experiment.load_design`); default the
        paper's (gait, frequency_hz). The manifest's columns are checked against it.
    """
    if pose is not None:
        pose.check()
    conditions = read_manifest(manifest, design) if manifest is not None else {}
    roles = read_layout(layout) if layout is not None else None
    exclude = {Path(p).resolve() for p in (manifest, layout) if p is not None}
    files = expand_paths(list(paths), exclude) if paths else sorted(conditions)
    if not files:
        raise IngestError(
            "nothing to ingest: give capture files, folders or manifest", param="manifest"
        )
    results = []
    source = str(layout) if layout else "layout"
    enabled = progress and len(files) > 1
    bar = progress_bar("Ingesting", total=len(files), enabled=enabled, unit="files")
    with store.locked("ingest"), bar as advance, store.writer() as conn:
        if design is not None and any(c.axes for c in conditions.values()):
            with conn.begin():
                check_axes(conn, design)
        for path in files:
            condition = conditions.get(Path(path).resolve())
            try:
                results.append(
                    ingest_file(store, path, condition, roles, source, conn, pose, design)
                )
            except IngestError as exc:
                if not keep_going:
                    raise
                results.append(IngestResult(Path(path), "failed", None, 0, str(exc), exc))
            advance()
    return results
