"""The fast paths of the learners give numpy's own bits, and the simulator's kernels can
be compiled ahead of first use."""

from __future__ import annotations

import numpy as np

from suds_exp.models import fourier
from suds_exp.models.mixture import exp_inplace, row_max


def _bits_equal(a, b) -> bool:
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def test_exp_inplace_is_numpys_exp_bit_for_bit_also_where_it_underflows():
    rng = np.random.default_rng(0)
    # normal, subnormal-result and underflowing arguments, and the special values
    a = np.concatenate(
        [
            rng.uniform(-50, 0, 3000),
            rng.uniform(-746, -708, 3000),
            rng.uniform(-5000, -746, 3000),
            [-745.13, -745.14, -746.0, -np.inf, 0.0, -0.0, np.nan, 3.0],
        ]
    )
    rng.shuffle(a)
    a = a.reshape(-1, 8)
    assert _bits_equal(exp_inplace(a.copy()), np.exp(a))
    small = rng.uniform(-3, 0, (40, 16))
    assert _bits_equal(exp_inplace(small.copy()), np.exp(small))


def test_row_max_is_numpys_row_max():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(500, 16)) * 100
    a[3, 5] = np.nan
    a[7, :] = -np.inf
    assert _bits_equal(row_max(a), a.max(axis=1))


def test_basis_derivative_from_the_basis_equals_the_direct_one():
    phase = np.random.default_rng(2).uniform(-20, 20, 777)
    for order in (0, 1, 3, 10):
        # the derivative computed from its own sines and cosines, as it was before
        m = np.arange(1, order + 1)
        arg = phase[:, None] * m[None, :]
        direct = np.zeros((len(phase), 2 * order + 1))
        direct[:, 1::2] = -m * np.sin(arg)
        direct[:, 2::2] = m * np.cos(arg)
        assert _bits_equal(fourier.derivative_of_basis(fourier.basis(phase, order)), direct)
        assert _bits_equal(fourier.basis_derivative(phase, order), direct)


def test_the_simulator_kernels_compile_ahead_of_first_use():
    from suds_exp.sim import files, rft
    from suds_exp.sim.precompile import compile_kernels

    assert compile_kernels() > 0
    for kernel in (rft.run_trials, rft.solve_twists, files._format_into):
        assert kernel.signatures, kernel


def test_as_array_is_the_loc_subset_bit_for_bit_in_its_layout():
    """Learners read their columns one by one (campaign speed); the array must be the
    one `.loc[:, columns].to_numpy(dtype=float)` gave, Fortran layout included (a BLAS
    product may round differently on another layout)."""
    import pandas as pd
    import pytest

    from suds_exp.models.base import ModelError, as_array

    rng = np.random.default_rng(2)
    n = 257
    frame = pd.DataFrame(
        {
            "trial_id": np.repeat([3, 4], [100, n - 100]),
            "ra_1": rng.normal(size=n),
            "flag": rng.random(n) > 0.5,
            "dra_1": rng.normal(size=n).astype(np.float32),
            "cycle": np.arange(n),
        }
    )
    frame["later"] = rng.normal(size=n)  # a second block, as a learner's added column
    columns = ["later", "ra_1", "trial_id", "dra_1", "flag", "cycle"]
    want = frame.loc[:, columns].to_numpy(dtype=float, copy=True)
    got = as_array(frame, tuple(columns), "test")
    assert _bits_equal(got, want)
    assert got.flags["F_CONTIGUOUS"] == want.flags["F_CONTIGUOUS"]
    assert got.flags["C_CONTIGUOUS"] == want.flags["C_CONTIGUOUS"]
    got[0, 0] = 1e9  # a copy: the frame is untouched
    assert frame["later"].iloc[0] != 1e9
    twice = pd.concat([frame[["ra_1"]], frame[["ra_1"]]], axis=1)  # duplicate names
    assert _bits_equal(as_array(twice, ["ra_1"], "t"), twice.loc[:, ["ra_1"]].to_numpy(float))
    frame.loc[5, "ra_1"] = np.nan
    with pytest.raises(ModelError, match="ra_1 hold NaN"):
        as_array(frame, ["ra_1"], "test")
