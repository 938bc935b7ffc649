"""Cleaning: every injected jump is found, clean points are never removed, gaps are filled
linearly, and a gap longer than allowed is refused with a message naming it."""

from __future__ import annotations

import numpy as np
import pytest

from suds_exp.errors import PreprocessError
from suds_exp.preprocess.clean import clean_tracks
from suds_exp.testing.synthetic_captures import synthetic_trial


@pytest.mark.parametrize("gait,freq", [("S+", 1.0), ("D+", 1.0), ("O", 1 / 3), ("S-", 0.5)])
def test_injected_jumps_are_all_found_and_clean_points_kept(gait, freq):
    found = injected = wrongly_removed = 0
    for seed in range(8):
        trial = synthetic_trial(gait, freq, n_cycles=6, n_jumps=12, n_dropouts=10, seed=seed)
        result = clean_tracks(trial.xyz, jump_mm=9.0)
        injected += int(trial.jumped.sum())
        found += int((result.removed & trial.jumped).sum())
        wrongly_removed += int((result.removed & ~trial.jumped).sum())
    assert injected > 100
    assert found == injected
    assert wrongly_removed == 0


def test_spike_loses_one_point_and_is_filled_linearly():
    n = 50
    xyz = np.zeros((n, 1, 3))
    xyz[:, 0, 0] = np.arange(n) * 2.0  # 2 mm per frame along x
    xyz[20, 0, 1] += 15.0  # a 15 mm spike
    result = clean_tracks(xyz, jump_mm=9.0)
    assert np.flatnonzero(result.removed[:, 0]).tolist() == [20]
    assert result.n_jumps == 2
    np.testing.assert_allclose(result.xyz[:, 0, 0], np.arange(n) * 2.0)
    np.testing.assert_allclose(result.xyz[:, 0, 1], 0.0)


def test_displaced_stretch_after_a_dropout_is_removed_and_only_it():
    n = 120
    t = np.arange(n)
    xyz = np.zeros((n, 1, 3))
    xyz[:, 0, 0] = 40 * np.sin(t / 10)  # fast, curved motion
    xyz[:, 0, 1] = 40 * np.cos(t / 10)
    xyz[50:58] = np.nan  # dropout
    xyz[58:61, 0, 2] += 20.0  # displaced right after it
    result = clean_tracks(xyz, jump_mm=9.0)
    assert np.flatnonzero(result.removed[:, 0]).tolist() == [58, 59, 60]
    assert result.filled[50:61, 0].all() and not result.filled[:50, 0].any()
    assert result.longest_gap == 11


def test_fractions_count_removed_and_filled_points():
    trial = synthetic_trial("O", 0.5, n_cycles=4, n_jumps=5, n_dropouts=4, seed=3)
    result = clean_tracks(trial.xyz)
    assert result.removed_fraction == pytest.approx(trial.jumped.mean())
    assert result.filled_fraction == pytest.approx((trial.jumped | trial.dropped).mean())
    assert np.isfinite(result.xyz).all()


def test_a_gap_longer_than_allowed_is_refused_naming_marker_and_frame():
    xyz = np.tile(np.arange(100.0)[:, None, None], (1, 2, 3))
    xyz[30:60, 1] = np.nan
    with pytest.raises(
        PreprocessError, match=r"marker b has a gap of 30 frames starting at frame index 30"
    ):
        clean_tracks(xyz, max_gap_frames=25, marker_names=["a", "b"])
    assert clean_tracks(xyz, max_gap_frames=30).longest_gap == 30


def test_a_marker_never_seen_is_refused():
    xyz = np.zeros((10, 2, 3))
    xyz[:, 0] = np.nan
    with pytest.raises(PreprocessError, match="marker a is never seen"):
        clean_tracks(xyz, marker_names=["a", "b"])


def test_two_jumps_a_few_frames_apart_on_a_ringing_spoke_cost_only_their_points(tmp_path):
    # Found on a simulated trial (D+ at 1 Hz, repeat 2, seed 0, with bed packing and
    # hinge friction): tail_spoke jumps at frames 1243 and 1256. The two clean runs on
    # either side were compared over the 15 frames between, as if those frames said
    # nothing, and the ringing spoke is not linear over 15 frames, so the whole
    # 1,243-frame run before the jumps was removed and preprocessing refused the trial.
    from suds_exp.ingest.qtm import read_qtm_tsv
    from suds_exp.sim import SimConfig, set_effect, simulate_dataset

    cfg = set_effect(SimConfig(), "bed_packing.trial_cv=0.25")
    cfg = set_effect(cfg, "hinge_friction.torque_n_mm=40")
    data = simulate_dataset(tmp_path, cfg, gaits=["D+"], frequencies_hz=[1.0], repeats=4)
    path = data.tsv_paths[1]
    capture = read_qtm_tsv(path, path.read_text())
    spoke = capture.marker_names.index("tail_spoke")
    track = capture.xyz[:, spoke : spoke + 1]
    steps = np.linalg.norm(np.diff(track[:, 0], axis=0), axis=1)
    jumps = np.flatnonzero(steps > 9.0)
    assert jumps.tolist() == [1242, 1243, 1255, 1256]  # the case as found
    result = clean_tracks(track)
    assert np.flatnonzero(result.removed[:, 0]).tolist() == [1243, 1256]
