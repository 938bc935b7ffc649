"""The learned connection fitted from the directions the data visited (fast: a known
linear map stands in for a learner)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from suds_exp.errors import ConfigError
from suds_exp.gait.connection import compare_connections, learned_connection

A0 = np.array([[10.0, -4.0], [2.0, 6.0], [0.1, -0.3]])  # (3 components, 2 joints)


class Linear:
    """v_b = A0 dr_a/dt, except that directions with dr_a/dt_2 > 0 are answered wrongly
    (as a learner extrapolating where it has no data would)."""

    def predict(self, frame):
        dra = frame[["dra_1", "dra_2"]].to_numpy(float)
        vb = dra @ A0.T
        vb[dra[:, 1] > 1e-9] *= 3.0
        return frame.assign(vx=vb[:, 0], vy=vb[:, 1], wz=vb[:, 2])


def _samples(directions) -> pd.DataFrame:
    """Shapes on a 0.05 rad lattice over [-0.5, 0.5]^2, each visited once in each of
    ``directions`` (unit vectors, rad/s)."""
    axis = np.arange(-0.5, 0.5001, 0.05)
    p = np.array([(a, b) for a in axis for b in axis])
    rows = [np.column_stack([p, np.tile(d, (len(p), 1))]) for d in directions]
    x = np.vstack(rows)
    return pd.DataFrame(
        {"trial_id": 1, "ra_1": x[:, 0], "ra_2": x[:, 1], "dra_1": x[:, 2], "dra_2": x[:, 3]}
    )


def test_visited_directions_recover_the_map_where_the_data_went():
    s = _samples([(1.0, 0.0), (-1.0, 0.0), (np.cos(2.5), -np.sin(2.5))])
    visited = learned_connection(Linear(), s, grid=11, half_range=0.4, directions="visited")
    uniform = learned_connection(Linear(), s, grid=11, half_range=0.4)
    ref = np.broadcast_to(A0, (11, 11, 3, 2))
    assert visited.inside.sum() == 121
    assert compare_connections(visited, ref)["mean"] < 1e-9
    assert compare_connections(uniform, ref)["mean"] > 0.3
    assert np.nanmin(visited.spread) > 0.05


def test_one_line_of_directions_has_no_spread():
    s = _samples([(1.0, 0.0), (-1.0, 0.0)])
    conn = learned_connection(Linear(), s, grid=5, half_range=0.4, directions="visited")
    np.testing.assert_allclose(conn.spread[conn.inside], 0.0, atol=1e-12)
    assert (
        compare_connections(conn, np.broadcast_to(A0, (5, 5, 3, 2)), min_spread=0.05)["n_inside"]
        == 0
    )


def test_unknown_directions_are_refused():
    with pytest.raises(ConfigError, match="directions"):
        learned_connection(Linear(), _samples([(1.0, 0.0)]), directions="some")
