"""The body hook of `preprocess`: what is specific to a body's geometry, behind one face.

`preprocess` reads markers, cleans them, fits what a version shares, and turns each
trial's body pose, actuated shape and passive state into samples (smoothing, passive PCA,
phase, rates, body velocity). Only the middle of that depends on the body: which markers
to read, how the cleaned markers become segment frames, what a version fits across trials
(the joint positions) and how frames and joints give the pose and shape. A `BodyModel`
does exactly that; `SwimmerModel` is the paper's swimmer (the pipeline's default), and
`suds_exp.body` builds one from any description of rigid segments.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from suds_exp.errors import PreprocessError
from suds_exp.ingest.layout import trial_layout
from suds_exp.preprocess.body_frame import Joints, SegmentFrames, fit_joints, noise_shift
from suds_exp.preprocess.chain import chain_settings
from suds_exp.preprocess.kinematics import Kinematics, kinematics, measure
from suds_exp.preprocess.params import params_seed
from suds_exp.robot import ROLES

#: `SwimmerModel.joints_warning` speaks when `noise_shift` moves a motor axis further than
#: this, mm. On the simulated robot (two dataset seeds) each gait alone but O, and O with
#: another gait, stay at or under 0.33 mm (joint angles within 0.004 rad of the truth);
#: O alone moves them 0.84-1.22 mm (0.014-0.017 rad). docs/results/preprocessing.md.
JOINT_SHIFT_WARN_MM = 0.5


class BodyModel:
    """The body-specific steps of `preprocess` (override every method).

    ``labels``: the names of the markers a trial is read as, in the order of the tracks
    the other methods receive (n_frames, len(labels), 3).
    """

    labels: tuple[str, ...] = ()

    def version_params(self, params: dict[str, Any]) -> dict[str, Any]:
        """The version's full parameters given the resolved ones (add what names the body,
        refuse what it cannot honour)."""
        return params

    def marker_names(self, layout: str | None) -> list[str]:
        """The trial's marker names of `labels`, in order (``layout``: its stored layout)."""
        raise NotImplementedError

    def missing(self, trial_id: int, lacking: Sequence[str]) -> str:
        """The one-line message for a trial lacking markers of these labels."""
        return f"trial {trial_id}: has no marker {', '.join(lacking)}"

    def measure(
        self, xyz: np.ndarray, params: dict[str, Any], filled: np.ndarray | None = None
    ) -> Any:
        """Per-trial geometry from cleaned tracks (n_frames, len(labels), 3) mm;
        ``filled`` (n_frames, len(labels)) bool marks the points cleaning interpolated."""
        raise NotImplementedError

    def interpolated_frames(self, measured: Any) -> int:
        """Frames of ``measured`` (summed over segments) whose pose rests on interpolated
        points; 0 for a model that does not tell."""
        return 0

    def fit_joints(self, measured: Sequence[Any], params: Mapping[str, Any] | None = None) -> Any:
        """What the version shares, fitted on the measured trials (the joint positions);
        ``params``: the version's parameters."""
        raise NotImplementedError

    def joints_warning(self, joints: Any) -> str | None:
        """One line when ``joints`` are poorly determined by the trials they were fitted
        on (None when they are not, or the model cannot tell)."""
        return None

    def joints_state(self, joints: Any) -> str:
        raise NotImplementedError

    def joints_from(self, state: str) -> Any:
        raise NotImplementedError

    def kinematics(
        self,
        measured: Any,
        joints: Any,
        params: dict[str, Any],
        rate_hz: float,
        frequency_hz: float | None,
    ) -> Kinematics:
        """Body pose, r_a and passive state of one trial."""
        raise NotImplementedError

    def stats(self, measured: Any, joints: Any) -> tuple[list[float], float, float]:
        """(plane normal (3,), mean and RMS deviation of the checked joint distance, mm)
        for the trial's `prep_trials` row."""
        raise NotImplementedError


class SwimmerModel(BodyModel):
    """The paper's swimmer: 11 markers by role (a trial's layout names them), head and tail
    frames from their top markers (the tail's refined by ``tail_fit``), motor axes at a
    constant distance (`fit_joints`), body pose from the segment frames or the chain fit."""

    labels = ROLES

    def marker_names(self, layout: str | None) -> list[str]:
        names = trial_layout(layout)
        return [names[r] for r in ROLES]

    def missing(self, trial_id: int, lacking: Sequence[str]) -> str:
        return (
            f"trial {trial_id}: has no marker for role(s) {', '.join(lacking)}; "
            "re-ingest it with a layout naming them"
        )

    def measure(self, xyz: np.ndarray, params: dict[str, Any], filled=None):
        return measure(xyz, params["tail_fit"])

    def fit_joints(
        self, measured: Sequence[Any], params: Mapping[str, Any] | None = None
    ) -> Joints:
        """The motor axes over the trials, at ``joint_distance_mm`` apart when it is given
        (> 0), with their `noise_shift` when ``params`` are given (seeded by their hash)."""
        frames = [m.frames for m in measured]
        pooled = SegmentFrames(
            *[
                np.concatenate([getattr(f, a) for f in frames])
                for a in ("head_origin", "head_angle", "tail_origin", "tail_angle")
            ]
        )
        known = (params or {}).get("joint_distance_mm") or None
        joints = fit_joints(pooled, known)
        if params is None:
            return joints
        seed = params_seed(params)
        return replace(joints, noise_shift_mm=noise_shift(frames, joints, known, seed))

    def joints_warning(self, joints: Joints) -> str | None:
        if not joints.noise_shift_mm > JOINT_SHIFT_WARN_MM:
            return None
        return (
            f"segment origins are poorly determined by these trials: noise like their own "
            f"moves the motor axes by {joints.noise_shift_mm:.1f} mm (fitted "
            f"{joints.length_mm:.1f} mm apart), so joint angles and body velocity may be "
            "biased by a few per cent; give the distance between the motor axes as "
            "--param joint_distance_mm=MM, or preprocess together with trials of a gait "
            "whose shape loop is not a circle"
        )

    def joints_state(self, joints: Joints) -> str:
        return json.dumps(
            {
                "head": joints.head.tolist(),
                "tail": joints.tail.tolist(),
                "length_mm": joints.length_mm,
                "rms_mm": joints.rms_mm,
                "noise_shift_mm": None
                if math.isnan(joints.noise_shift_mm)
                else joints.noise_shift_mm,
            }
        )

    def joints_from(self, state: str) -> Joints:
        d = json.loads(state)
        shift = d.get("noise_shift_mm")
        return Joints(
            np.asarray(d["head"]),
            np.asarray(d["tail"]),
            d["length_mm"],
            d["rms_mm"],
            float("nan") if shift is None else shift,
        )

    def kinematics(self, measured, joints, params, rate_hz, frequency_hz) -> Kinematics:
        chain = chain_settings(params, rate_hz, frequency_hz, len(measured.local))
        return kinematics(measured, joints, chain, params["ra_repr"])

    def stats(self, measured, joints: Joints) -> tuple[list[float], float, float]:
        head, tail = joints.points(measured.frames)
        # this trial's distance between the segment origins (constant if the fit holds here)
        dist = np.hypot(*(head - tail).T)
        return measured.plane.basis[2].tolist(), float(dist.mean()), float(dist.std())


def require_markers(model: BodyModel, trial_id: int, present: np.ndarray) -> None:
    """Raise `PreprocessError` unless label numbers ``present`` cover every label."""
    have = set(int(i) for i in present)
    lacking = [model.labels[i] for i in range(len(model.labels)) if i not in have]
    if lacking:
        raise PreprocessError(model.missing(trial_id, lacking))
