"""Which joints a gait moves: a version's actuated joints, and a gait matched to them.

A gait file names its columns after the body's actuated joints (`suds_exp.gait.shape`).
A preprocessing version of a segment body holds r_a in the description's order of its
actuated joints (columns ra_1 .. ra_m); the built-in swimmer's, and a chain body's
first two shape modes, are phi1 and phi2. A gait is matched by name, never by position:
a column naming no joint of the body, or a joint without a column, is refused in one
line (a 2-joint gait on a 1-joint body used to lose its second joint without a word).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from suds_exp.errors import ConfigError
from suds_exp.gait.shape import SWIMMER_JOINTS, FourierGait, Gait


def version_joints(params: Mapping[str, Any]) -> tuple[str, ...]:
    """The actuated joints' names of a version with parameters ``params``, in the order of
    its columns ra_1 .. ra_m: a segment body's (under ``body``) or phi1, phi2."""
    body = params.get("body")
    if isinstance(body, dict) and body.get("joints"):
        return tuple(j["name"] for j in body["joints"] if j["kind"] == "actuated")
    return SWIMMER_JOINTS


def body_label(params: Mapping[str, Any]) -> str:
    """The body's name for messages: a described body's ``name``, else the swimmer."""
    body = params.get("body")
    return str(body.get("name", "described")) if isinstance(body, dict) else "swimmer"


def is_swimmer(params: Mapping[str, Any]) -> bool:
    """True for a version of the paper's swimmer (built-in, or its description): the one
    body the simulator moves (``--compare``, ``--verify``)."""
    body = params.get("body")
    if not isinstance(body, dict):
        return True
    return body.get("name") == "swimmer" and version_joints(params) == SWIMMER_JOINTS


def describe(version_name: str, params: Mapping[str, Any]) -> str:
    """The version and its body's actuated joints, for messages: ``version NAME (body
    'B': 2 actuated joints, q1, q2)``."""
    joints = version_joints(params)
    return (
        f"version {version_name} (body {body_label(params)!r}: {len(joints)} actuated "
        f"joint{'s' if len(joints) != 1 else ''}, {', '.join(joints)})"
    )


def match_joints(gait: Gait, joints: Sequence[str], where: str) -> Gait:
    """``gait`` with its columns in the order of ``joints`` (the body's actuated joints).

    Raises ConfigError (one line starting with ``where``) for a column that names no joint
    of the body, or a joint of the body the gait has no column for.
    """
    joints = tuple(joints)
    have = tuple(gait.joints)
    if have == joints:
        return gait
    unknown = [j for j in have if j not in joints]
    if unknown:
        listed = ", ".join(repr(j) for j in unknown)
        names = "column {} names" if len(unknown) == 1 else "columns {} name"
        raise ConfigError(
            f"{where}: {names.format(listed)} no joint of the body; its actuated joints are "
            f"{', '.join(joints)} (one column each, named as the body's joints)",
            param="gait_file",
        )
    missing = [j for j in joints if j not in have]
    if missing:
        raise ConfigError(
            f"{where}: no column for joint {missing[0]!r}; the body's actuated joints are "
            f"{', '.join(joints)} (one column each)",
            param="gait_file",
        )
    order = [have.index(j) for j in joints]
    if isinstance(gait, FourierGait):
        return FourierGait(gait.a0[order], gait.a[:, order], gait.b[:, order], gait.name, joints)
    return Reordered(gait, np.array(order), joints)


@dataclass
class Reordered(Gait):
    """A gait's columns taken in the order ``order`` (indices into its joints)."""

    gait: Gait
    order: np.ndarray
    joints: tuple[str, ...]

    @property
    def name(self) -> str:  # type: ignore[override]
        return self.gait.name

    def shape(self, theta) -> np.ndarray:
        return self.gait.shape(theta)[..., self.order]

    def rate(self, theta) -> np.ndarray:
        return self.gait.rate(theta)[..., self.order]
