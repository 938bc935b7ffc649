"""Body descriptions: the built-in swimmer, chains, and one-line errors for bad ones."""

from __future__ import annotations

import numpy as np
import pytest

from suds_exp.body import BodyError, chain_geometry, load_body, parse_body
from suds_exp.ingest import ROLES


def test_builtin_swimmer_names_the_robot_roles():
    body = load_body("swimmer")
    assert body.kind == "segments" and body.is_swimmer()
    assert sorted(body.markers) == sorted(ROLES)
    assert [(j.name, j.kind) for j in body.joints] == [("phi1", "actuated"), ("phi2", "actuated")]
    assert set(body.passive_markers) == {"flipper_1", "flipper_2", "flipper_3", "flipper_4"}


CHAIN = """
name = "eel"
[chain]
markers = ["a", "b", "c", "d", "e"]
modes = 3
"""

SEGMENTS = """
name = "two links"
[segments.front]
markers = { f1 = "top", f2 = "top" }
[segments.back]
markers = { b1 = "top", b2 = "top" }
[[joints]]
name = "hinge"
parent = "front"
child = "back"
kind = "passive"
"""


def test_chain_and_segments_parse():
    chain = parse_body(CHAIN, "eel.toml")
    assert chain.kind == "chain" and chain.markers == ["a", "b", "c", "d", "e"]
    two = parse_body(SEGMENTS, "two.toml")
    assert two.markers == ["f1", "f2", "b1", "b2"] and not two.is_swimmer()


BAD = {
    "segment with one marker": (
        SEGMENTS.replace('markers = { b1 = "top", b2 = "top" }', 'markers = { b1 = "top" }'),
        "segments.back: 1 marker(s); a rigid segment needs at least 2",
    ),
    "joint to an unknown segment": (
        SEGMENTS.replace('child = "back"', 'child = "bak"'),
        "joints[0] 'hinge': child 'bak' is not a segment",
    ),
    "cycle of joints": (
        SEGMENTS
        + '[[joints]]\nname = "loop"\nparent = "back"\nchild = "front"\nkind = "passive"\n',
        "joints[1] 'loop': joins 'back' and 'front', which are already connected (a cycle)",
    ),
    "cycle in chain": (
        CHAIN.replace('"e"]', '"e", "b"]'),
        "chain.markers[5]: marker 'b' already at position 1",
    ),
    "marker on two segments": (
        SEGMENTS.replace('b1 = "top", b2', 'f1 = "top", b2'),
        "segments.back.markers.f1: already on segment 'front'",
    ),
    "unknown joint kind": (
        SEGMENTS.replace('kind = "passive"', 'kind = "motor"'),
        "joints[0] 'hinge': kind 'motor'; expected actuated or passive",
    ),
    "unknown entry": (CHAIN.replace("modes = 3", "mode = 3"), "chain: unknown entry 'mode'"),
    "both kinds": (CHAIN + SEGMENTS.split("\n", 2)[2], "expected either [segments.*] or [chain]"),
    "too many modes": (CHAIN.replace("modes = 3", "modes = 4"), "chain.modes: 4"),
    "not toml": ("name = ", "not valid TOML"),
    "frame marker of another segment": (
        SEGMENTS.replace('b2 = "top" }', 'b2 = "top" }\nframe = ["b1", "f1"]'),
        "segments.back.frame: expected a list of the segment's own markers (b1, b2)",
    ),
    "a segment with two parent joints": (
        SEGMENTS.replace('markers = { b1 = "top", b2 = "top" }', 'markers = { b1 = "t", b2 = "t" }')
        + '[segments.side]\nmarkers = { s1 = "t", s2 = "t" }\n'
        + '[[joints]]\nname = "other"\nparent = "side"\nchild = "back"\nkind = "passive"\n',
        "joints[1] 'other': 'back' is already the child of joint 'hinge'",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_description_is_one_line_naming_the_entry(case):
    text, expected = BAD[case]
    with pytest.raises(BodyError) as err:
        parse_body(text, "body.toml")
    message = str(err.value)
    assert message.startswith("body.toml: ") and expected in message, message
    assert "\n" not in message


def test_chain_angles_of_a_known_shape():
    # markers on an arc of radius R, head first, spaced by s: each chord turns by s / R
    radius, s, n = 500.0, 50.0, 8
    arc = np.arange(n) * s / radius
    xy = radius * np.column_stack([np.sin(arc), 1 - np.cos(arc)])
    shift = np.array([10.0, -4.0])
    frames = np.stack([np.column_stack([xy + shift * i, np.full(n, 7.0)]) for i in range(3)])
    geom = chain_geometry(frames[:, ::-1] * [1, 1, 1], "z")  # head at the arc's far end
    np.testing.assert_allclose(np.abs(geom.angles), s / radius, atol=1e-12)
    assert np.all(np.sign(geom.angles) == np.sign(geom.angles[0, 0]))
    np.testing.assert_allclose(np.diff(geom.origin, axis=0), [shift, shift], atol=1e-9)
    np.testing.assert_allclose(geom.length, (n - 1) * 2 * radius * np.sin(s / radius / 2))
