"""Mocap ingest: QTM TSV, Vicon Nexus CSV, Motive CSV, TRC, C3D and CSV readers sharing
one parsing core, keypoint files through `movement`, manifest, marker layout, and the
experiment description kept with the data (`stored_design`, `add_trial_levels`)."""

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
