"""Mocap ingest: QTM TSV, Vicon Nexus CSV, Motive CSV, TRC, C3D and CSV readers sharing
one parsing core, keypoint files through `movement`, manifest, marker layout, and the
experiment description kept with the data (`stored_design`, `add_trial_levels`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from suds_exp.lazy import exports

if TYPE_CHECKING:  # what the names are, for readers and static tools; loaded on first use
    from suds_exp.ingest.capture import Capture
    from suds_exp.ingest.experiment import (
        add_trial_levels,
        design_for,
        stored_design,
        trial_level_axis,
    )
    from suds_exp.ingest.layout import DEFAULT_LAYOUT, ROLES, read_layout, trial_layout
    from suds_exp.ingest.listing import list_trials
    from suds_exp.ingest.load import IngestResult, ingest_file, ingest_paths
    from suds_exp.ingest.manifest import GAITS, Condition, read_manifest
    from suds_exp.ingest.pose import DEFAULT_CONFIDENCE, PoseOptions
    from suds_exp.ingest.readers import read_capture

#: Where each public name lives. Loaded on first use (PEP 562), so that `suds-exp status`
#: reads the stored design (suds_exp.ingest.experiment) without the capture readers.
_HOMES = {
    "Capture": "suds_exp.ingest.capture",
    "add_trial_levels": "suds_exp.ingest.experiment",
    "design_for": "suds_exp.ingest.experiment",
    "stored_design": "suds_exp.ingest.experiment",
    "trial_level_axis": "suds_exp.ingest.experiment",
    "DEFAULT_LAYOUT": "suds_exp.ingest.layout",
    "ROLES": "suds_exp.ingest.layout",
    "read_layout": "suds_exp.ingest.layout",
    "trial_layout": "suds_exp.ingest.layout",
    "list_trials": "suds_exp.ingest.listing",
    "IngestResult": "suds_exp.ingest.load",
    "ingest_file": "suds_exp.ingest.load",
    "ingest_paths": "suds_exp.ingest.load",
    "GAITS": "suds_exp.ingest.manifest",
    "Condition": "suds_exp.ingest.manifest",
    "read_manifest": "suds_exp.ingest.manifest",
    "DEFAULT_CONFIDENCE": "suds_exp.ingest.pose",
    "PoseOptions": "suds_exp.ingest.pose",
    "read_capture": "suds_exp.ingest.readers",
}


__all__ = [
    "Capture",
    "Condition",
    "DEFAULT_CONFIDENCE",
    "DEFAULT_LAYOUT",
    "GAITS",
    "IngestResult",
    "PoseOptions",
    "ROLES",
    "add_trial_levels",
    "design_for",
    "ingest_file",
    "ingest_paths",
    "list_trials",
    "read_capture",
    "read_layout",
    "read_manifest",
    "stored_design",
    "trial_level_axis",
    "trial_layout",
]

__getattr__, __dir__ = exports(__name__, _HOMES, __all__)
