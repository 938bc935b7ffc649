"""The real flying-snake glide end to end (slow: ingest, preprocess, three learners)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from suds_exp.body.real_snake import CHAIN_MODELS, run_real_snake


@pytest.mark.slow
def test_flying_snake_glide_end_to_end(shared, tmp_path):
    body = Path(__file__).resolve().parents[1] / "examples" / "flying_snake.toml"
    capture = shared / "refdata" / "flying_snake_qualisys" / "413_91.tsv"
    out = run_real_snake([capture], body, tmp_path / "snake.duckdb")
    # a travelling wave: the first two shape modes carry most of the chord-angle variance
    assert sum(out["explained_variance_ratio"][:2]) > 0.6
    # Yeaton et al. 2020: flying snakes undulate at about 1-2 Hz in glides
    assert 1.0 < out["phase_rate_hz"][0] < 2.0
    errors = out["errors"]
    assert errors.model.tolist() == ["constant", *CHAIN_MODELS]
    assert np.isfinite(errors[["vx_pct", "vy_pct", "wz_pct"]].to_numpy()).all()
    assert (errors.n_test > 50).all() and (errors.n_train > errors.n_test).all()
