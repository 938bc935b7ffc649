"""Body descriptions: which markers sit where on an articulated body (TOML).

Two kinds of body:

- **segments**: rigid segments, each with its markers and their roles (at least 2
  markers, or none with ``from_joints = true`` when the segment is located by its joints,
  as the swimmer's middle segment is; then ``length_mm``, the distance between its two
  joints, can be given when it is known, or it is fitted), joints between segments (``actuated`` or
  ``passive``; they must form one tree that connects every segment, in which each
  segment is the child of at most one joint), and passive markers hanging from a
  segment. ``frame`` lists the markers fixed
  on a segment that give its pose (default: all of them; the first two set its origin,
  their midpoint, and its first direction); its other markers are measured in its frame
  as passive state, like the passive markers. A joint's angle is its bend: zero when the
  two segments are in line, positive when the child turns counter-clockwise seen from
  above (`suds_exp.body.segments` defines it exactly); it does not depend on which
  segment is the body frame or on the order joints are listed, and writing a joint's
  parent and child the other way round flips its sign. Write each joint from the tail
  side (parent) to the head side (child) to get the swimmer's signs::

      name = "swimmer"
      body_frame = "middle"
      [segments.head]
      markers = { head_top_1 = "top", head_top_2 = "top", head_spoke = "spoke" }
      frame = ["head_top_1", "head_top_2"]
      [[joints]]
      name = "phi1"
      parent = "middle"
      child = "head"
      kind = "actuated"
      [passive_markers]
      flipper_1 = "head"

- **chain**: markers along a continuous body (snake, fish, eel), head to tail::

      name = "snake"
      [chain]
      markers = ["head", "m2", "m3", "tail"]
      up = "z"      # lab axis the shape is projected along
      modes = 4     # shape modes kept (PCA of the angles between successive chords)

A bad description raises `BodyError` in one line naming the file and the entry.
"""

from __future__ import annotations

import hashlib
import json
import tomllib
from dataclasses import asdict, dataclass, field
from importlib import resources
from pathlib import Path

from suds_exp.errors import BodyError
from suds_exp.ingest.layout import ROLES

JOINT_KINDS = ("actuated", "passive")
UP_AXES = ("x", "y", "z")
#: Names of the descriptions shipped in the package (``--body swimmer``).
BUILTIN = ("swimmer",)


@dataclass(frozen=True)
class Segment:
    name: str
    #: marker name -> role on the segment (free text, e.g. "top", "spoke")
    markers: dict[str, str]
    from_joints: bool = False
    #: the markers that give the segment's pose, in order (empty: all its markers)
    frame: list[str] = field(default_factory=list)
    #: from_joints only: the distance between its two joints when it is known (the
    #: robot's drawing), mm; None = fitted from the trials
    length_mm: float | None = None

    @property
    def frame_markers(self) -> list[str]:
        return list(self.frame) if self.frame else list(self.markers)


@dataclass(frozen=True)
class Joint:
    name: str
    parent: str
    child: str
    kind: str  # actuated | passive


@dataclass(frozen=True)
class Chain:
    #: marker names from head to tail
    markers: list[str]
    up: str = "z"
    modes: int = 4


@dataclass(frozen=True)
class Body:
    """A parsed body description: ``segments``/``joints``/``passive_markers``, or ``chain``."""

    name: str
    source: str
    segments: list[Segment] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)
    passive_markers: dict[str, str] = field(default_factory=dict)
    body_frame: str | None = None
    chain: Chain | None = None

    @property
    def kind(self) -> str:
        return "chain" if self.chain is not None else "segments"

    @property
    def markers(self) -> list[str]:
        """Every marker the description names, in its order."""
        if self.chain is not None:
            return list(self.chain.markers)
        return [m for s in self.segments for m in s.markers] + list(self.passive_markers)

    def is_swimmer(self) -> bool:
        """True for the paper's swimmer: the 11 roles on head/middle/tail, two motors."""
        actuated = {frozenset((j.parent, j.child)) for j in self.joints if j.kind == "actuated"}
        return (
            self.chain is None
            and sorted(self.markers) == sorted(ROLES)
            and actuated == {frozenset(("middle", "head")), frozenset(("middle", "tail"))}
            and self.body_frame == "middle"
        )

    def to_dict(self) -> dict:
        """Everything that defines the body (not its file), for a version's parameters."""
        d = asdict(self)
        d.pop("source")
        for seg in d.get("segments", []):
            # unset, it is left out: descriptions without it keep their versions
            if seg.get("length_mm") is None:
                seg.pop("length_mm", None)
        return d

    def digest(self) -> str:
        return hashlib.sha256(json.dumps(self.to_dict(), sort_keys=True).encode()).hexdigest()


def _table(src: str, value, where: str) -> dict:
    if not isinstance(value, dict):
        raise BodyError(f"{src}: {where}: expected a table")
    return value


def _known_keys(src: str, table: dict, allowed: tuple[str, ...], where: str) -> None:
    for key in table:
        if key not in allowed:
            raise BodyError(
                f"{src}: {where}: unknown entry {key!r}; expected one of {', '.join(allowed)}"
            )


def load_body(path: str | Path) -> Body:
    """Read a body description: a TOML file, or the name of a built-in one (`BUILTIN`)."""
    if str(path) in BUILTIN:
        text = resources.files("suds_exp.body").joinpath(f"{path}.toml").read_text()
        return parse_body(text, f"built-in body {path!r}")
    path = Path(path)
    if not path.is_file():
        raise BodyError(
            f"{path}: body description not found (a TOML file, or one of {', '.join(BUILTIN)})"
        )
    return parse_body(path.read_text(), str(path))


def parse_body(text: str, source: str) -> Body:
    """Parse and check the TOML text of a body description; ``source`` names it in errors."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise BodyError(f"{source}: not valid TOML ({exc})") from None
    _known_keys(
        source,
        doc,
        ("name", "body_frame", "segments", "joints", "passive_markers", "chain"),
        "top level",
    )
    name = doc.get("name")
    if not isinstance(name, str) or not name.strip():
        raise BodyError(f"{source}: name: expected the body's name as text")
    if ("chain" in doc) == ("segments" in doc):
        raise BodyError(f"{source}: expected either [segments.*] or [chain], not both or neither")
    if "chain" in doc:
        extra = [k for k in ("joints", "passive_markers", "body_frame") if k in doc]
        if extra:
            raise BodyError(f"{source}: {extra[0]}: not used by a [chain] body")
        return Body(name, source, chain=_parse_chain(source, _table(source, doc["chain"], "chain")))
    return _parse_segments(source, name, doc)


def _parse_chain(src: str, table: dict) -> Chain:
    _known_keys(src, table, ("markers", "up", "modes"), "chain")
    markers = table.get("markers")
    if not isinstance(markers, list) or not all(isinstance(m, str) and m for m in markers):
        raise BodyError(f"{src}: chain.markers: expected a list of marker names, head to tail")
    seen: dict[str, int] = {}
    for i, m in enumerate(markers):
        if m in seen:
            raise BodyError(
                f"{src}: chain.markers[{i}]: marker {m!r} already at position {seen[m]}; a chain "
                "runs head to tail once and cannot loop back (cycle)"
            )
        seen[m] = i
    if len(markers) < 4:
        raise BodyError(
            f"{src}: chain.markers: {len(markers)} markers; a chain needs at least 4 "
            "(two angles between successive chords)"
        )
    up = table.get("up", "z")
    if up not in UP_AXES:
        raise BodyError(f"{src}: chain.up: {up!r}; expected one of {', '.join(UP_AXES)}")
    modes = table.get("modes", 4)
    n_angles = len(markers) - 2
    if not isinstance(modes, int) or isinstance(modes, bool) or not 3 <= modes <= min(n_angles, 14):
        raise BodyError(
            f"{src}: chain.modes: {modes!r}; expected a whole number from 3 to "
            f"{min(n_angles, 14)} (the {n_angles} chord angles of {len(markers)} markers)"
        )
    return Chain(list(markers), up, modes)


def _parse_segments(src: str, name: str, doc: dict) -> Body:
    segments: list[Segment] = []
    owner: dict[str, str] = {}
    for seg_name, raw in _table(src, doc["segments"], "segments").items():
        where = f"segments.{seg_name}"
        raw = _table(src, raw, where)
        _known_keys(src, raw, ("markers", "from_joints", "frame", "length_mm"), where)
        markers = _table(src, raw.get("markers", {}), f"{where}.markers")
        frame = raw.get("frame", [])
        if not isinstance(frame, list) or any(m not in markers for m in frame):
            raise BodyError(
                f"{src}: {where}.frame: expected a list of the segment's own markers "
                f"({', '.join(markers)})"
            )
        if frame and len(frame) < 2:
            raise BodyError(
                f"{src}: {where}.frame: {len(frame)} marker(s); a segment's pose needs at least 2"
            )
        from_joints = raw.get("from_joints", False) is True
        if from_joints and markers:
            raise BodyError(f"{src}: {where}: from_joints = true but it also lists markers")
        if not from_joints and len(markers) < 2:
            raise BodyError(
                f"{src}: {where}: {len(markers)} marker(s); a rigid segment needs at least 2 "
                "to give its orientation (or from_joints = true)"
            )
        length = raw.get("length_mm")
        if length is not None and (
            not from_joints
            or isinstance(length, bool)
            or not isinstance(length, int | float)
            or not length > 0
        ):
            raise BodyError(
                f"{src}: {where}.length_mm: expected a distance > 0 (mm) between the joints "
                "of a from_joints segment"
            )
        for marker, role in markers.items():
            if not isinstance(role, str):
                raise BodyError(f"{src}: {where}.markers.{marker}: expected its role as text")
            if marker in owner:
                raise BodyError(
                    f"{src}: {where}.markers.{marker}: already on segment {owner[marker]!r}"
                )
            owner[marker] = seg_name
        segments.append(
            Segment(
                seg_name,
                dict(markers),
                from_joints,
                list(frame),
                None if length is None else float(length),
            )
        )
    names = [s.name for s in segments]
    joints = []
    raw_joints = doc.get("joints", [])
    if not isinstance(raw_joints, list):
        raise BodyError(f"{src}: joints: expected [[joints]] entries")
    for i, raw in enumerate(raw_joints):
        where = f"joints[{i}]"
        raw = _table(src, raw, where)
        _known_keys(src, raw, ("name", "parent", "child", "kind"), where)
        label = f"{where} {raw.get('name', '')!r}"
        for end in ("parent", "child"):
            if raw.get(end) not in names:
                raise BodyError(
                    f"{src}: {label}: {end} {raw.get(end)!r} is not a segment ({', '.join(names)})"
                )
        if raw.get("kind") not in JOINT_KINDS:
            raise BodyError(
                f"{src}: {label}: kind {raw.get('kind')!r}; expected actuated or passive"
            )
        joints.append(
            Joint(str(raw.get("name", f"joint_{i + 1}")), raw["parent"], raw["child"], raw["kind"])
        )
    _check_tree(src, names, joints)
    passive = _table(src, doc.get("passive_markers", {}), "passive_markers")
    for marker, seg in passive.items():
        if seg not in names:
            raise BodyError(
                f"{src}: passive_markers.{marker}: segment {seg!r} is not one of {', '.join(names)}"
            )
        if marker in owner:
            raise BodyError(
                f"{src}: passive_markers.{marker}: already on segment {owner[marker]!r}"
            )
    frame = doc.get("body_frame", names[0] if names else None)
    if frame not in names:
        raise BodyError(f"{src}: body_frame: {frame!r} is not a segment ({', '.join(names)})")
    for seg in segments:
        if seg.from_joints and not any(seg.name in (j.parent, j.child) for j in joints):
            raise BodyError(f"{src}: segments.{seg.name}: from_joints = true but no joint has it")
    _check_connected(src, names, joints, frame)
    return Body(name, src, segments, joints, dict(passive), frame)


def _check_connected(src: str, names: list[str], joints: list[Joint], frame: str) -> None:
    """Refuse a segment the joints do not connect to the body frame's segment (its
    markers would otherwise be read and silently left out)."""
    reached, todo = {frame}, [frame]
    while todo:
        here = todo.pop()
        for j in joints:
            for near, far in ((j.parent, j.child), (j.child, j.parent)):
                if near == here and far not in reached:
                    reached.add(far)
                    todo.append(far)
    for name in names:
        if name not in reached:
            raise BodyError(
                f"{src}: segments.{name}: joined to no other segment; every segment must be "
                "connected to the body by joints (add a [[joints]] entry or remove the segment)"
            )


def _check_tree(src: str, names: list[str], joints: list[Joint]) -> None:
    """Refuse a joint that closes a loop (the segments and joints must form a tree)."""
    root = {n: n for n in names}

    def find(n: str) -> str:
        while root[n] != n:
            n = root[n]
        return n

    parent_of: dict[str, str] = {}
    for i, j in enumerate(joints):
        if j.child in parent_of:
            raise BodyError(
                f"{src}: joints[{i}] {j.name!r}: {j.child!r} is already the child of joint "
                f"{parent_of[j.child]!r}; a segment has at most one parent joint (write "
                "each joint from the tail side to the head side)"
            )
        parent_of[j.child] = j.name
        a, b = find(j.parent), find(j.child)
        if a == b:
            raise BodyError(
                f"{src}: joints[{i}] {j.name!r}: joins {j.parent!r} and {j.child!r}, which "
                "are already connected (a cycle); joints must form a tree"
            )
        root[a] = b


def check_markers(body: Body, marker_names: list[str], trial: str) -> None:
    """Raise `BodyError` unless the trial has every marker the description names."""
    have = set(marker_names)
    for marker in body.markers:
        if marker not in have:
            raise BodyError(
                f"{body.source}: marker {marker!r} is unknown to {trial}; its markers are "
                f"{', '.join(marker_names)}"
            )
