"""Body descriptions (TOML): rigid segments with joints and passive markers, or a marker
chain; the preprocessing they drive."""

from suds_exp.body.chain_shape import ChainGeometry, chain_geometry
from suds_exp.body.description import (
    BUILTIN,
    Body,
    BodyError,
    Chain,
    Joint,
    Segment,
    check_markers,
    load_body,
    parse_body,
)
from suds_exp.body.prep import preprocess_body
from suds_exp.body.segments import SegmentModel

__all__ = [
    "BUILTIN",
    "Body",
    "BodyError",
    "Chain",
    "ChainGeometry",
    "Joint",
    "Segment",
    "SegmentModel",
    "chain_geometry",
    "check_markers",
    "load_body",
    "parse_body",
    "preprocess_body",
]
