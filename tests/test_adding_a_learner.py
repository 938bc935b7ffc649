"""Adding a learner takes two places: its class and one registry entry.

The worked example of docs/architecture.md ("Where a newcomer adds ..."): a toy learner
is written here (place 1) and registered for the test only (place 2, in production a line
of `suds_exp.vocabulary.REGISTRY`); `make_model`, its hyper-parameter checks, scikit-learn's
`get_params`/`clone` and the SQL table ``learners`` then know it, and forget it after.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from sklearn.base import clone

from suds_exp import vocabulary
from suds_exp.errors import ConfigError
from suds_exp.models import make_model
from suds_exp.models.base import Learner, as_array
from suds_exp.models.params import Param, Real
from suds_exp.robot import VB_COLUMNS


class ToyLearner(Learner):
    """Place 1: the learner. Predicts the training mean body velocity times `scale`."""

    name = "Toy"
    _hyper_parameters = {"scale": Param(1.0, Real(0.0, strict=True))}

    def fit(self, samples: pd.DataFrame, y=None):
        self._validate()
        self.mean_ = as_array(samples, VB_COLUMNS, self.name).mean(axis=0)
        self.n_features_in_ = 0
        return self

    def predict(self, samples: pd.DataFrame) -> pd.DataFrame:
        self._check_fitted()
        values = np.tile(self.scale * self.mean_, (len(samples), 1))
        return self._output_frame(values, samples)


@pytest.fixture
def toy(monkeypatch):
    """Place 2: the registry entry (in production: one line in REGISTRY)."""
    info = vocabulary.LearnerInfo(
        "Toy", "Toy", False, frozenset(), f"{ToyLearner.__module__}:ToyLearner"
    )
    monkeypatch.setattr(vocabulary, "REGISTRY", (*vocabulary.REGISTRY, info))
    return monkeypatch


SAMPLES = pd.DataFrame({"vx": [1.0, 3.0], "vy": [0.0, 2.0], "wz": [0.5, 0.5]})


def test_a_registered_learner_is_built_checked_and_cloned_by_name(toy):
    model = make_model("Toy", scale=2.0)
    assert model.get_params() == {"scale": 2.0}
    assert clone(model).get_params() == {"scale": 2.0}
    pred = model.fit(SAMPLES).predict(SAMPLES)
    np.testing.assert_array_equal(pred.to_numpy(), [[4.0, 2.0, 1.0]] * 2)
    with pytest.raises(ConfigError, match=r"^Toy: scale=0; expected a number > 0.0$"):
        make_model("Toy", scale=0).fit(SAMPLES)
    with pytest.raises(ConfigError, match="unknown parameter"):
        make_model("Toy", shift=1.0)


def test_the_sql_vocabulary_follows_the_registry_both_ways(toy, tmp_path):
    from suds_exp.store import Store

    def toy_rows():
        return Store(db).query_df("SELECT * FROM learners WHERE name = 'Toy'")

    db = tmp_path / "x.duckdb"
    Store(db).upgrade()
    rows = toy_rows()
    assert rows[["family", "suds", "paper", "survey"]].values.tolist() == [
        ["Toy", False, False, False]
    ]
    toy.undo()  # the learner is removed from the registry: the next upgrade drops its row
    with pytest.raises(ConfigError, match="unknown model 'Toy'"):
        make_model("Toy")
    Store(db).upgrade()
    assert toy_rows().empty
