"""The learner registry is the one home of learner names: the model lists, `make_model`
and the SQL table ``learners`` all follow it."""

from __future__ import annotations

import inspect

import pytest

from suds_exp.commands.campaign import parse_campaign_options
from suds_exp.errors import ConfigError
from suds_exp.models import (
    BASELINE_NAMES,
    FINSLER_MODELS,
    MODEL_NAMES,
    MODELS,
    MOMENTUM_MODELS,
    ONLINE_MODELS,
    builder,
    make_model,
)
from suds_exp.models.baselines import BASELINES
from suds_exp.models.registry import (
    ADAPTER,
    FINSLER_LEARNERS,
    LEARNERS,
    MOMENTUM_LEARNERS,
    REGISTRY,
    SUDS_SUFFIX,
    SURVEY_LEARNERS,
    tagged,
)


def test_the_paper_five_in_its_order():
    assert LEARNERS == ("phase-only", "TLS", "TLS+SUDS", "GMR", "GMR+SUDS")
    assert MODEL_NAMES == LEARNERS


def test_survey_is_the_five_and_the_baselines_it_names():
    assert SURVEY_LEARNERS == (*LEARNERS, "MLP", "MLP+SUDS", "GBT", "kNN", "KRR")
    assert list(parse_campaign_options(models="survey").models) == list(SURVEY_LEARNERS)


def test_baselines_and_online_learners_match_their_builders():
    assert BASELINE_NAMES == tuple(n for b in BASELINES for n in (b, b + SUDS_SUFFIX))
    assert tagged("online") == tuple(ONLINE_MODELS)


@pytest.mark.parametrize("info", REGISTRY, ids=lambda i: i.name)
def test_every_entry_builds_and_its_suds_flag_matches_its_name(info):
    make_model(info.name)
    # a suffix after +SUDS adds to the SUDS learner (GMR+SUDS+P: with momentum)
    assert info.suds == (SUDS_SUFFIX in info.name)
    assert info.family in info.name


@pytest.mark.parametrize("info", REGISTRY, ids=lambda i: i.name)
def test_every_entry_is_built_by_its_builder_under_its_name(info):
    model = make_model(info.name)
    assert type(model) is builder(info.name)
    # a baseline shows its scikit-learn class's name (sklearn:MLPRegressor)
    assert model.name == info.name or info.builder == ADAPTER


def test_the_model_lists_are_the_registry_by_tag():
    assert list(MODELS) == list(LEARNERS)
    assert list(ONLINE_MODELS) == list(tagged("online"))
    assert list(MOMENTUM_MODELS) == list(MOMENTUM_LEARNERS)
    assert list(FINSLER_MODELS) == list(FINSLER_LEARNERS)
    assert all(MODELS[n] is builder(n) for n in MODELS)


def test_unknown_tag_is_refused():
    with pytest.raises(ValueError, match="expected one of"):
        tagged("papers")


def test_the_sql_vocabulary_table_equals_the_registry(tmp_path):
    from suds_exp.store import Store

    store = Store(tmp_path / "x.duckdb")
    store.upgrade()
    table = store.query_df("SELECT * FROM learners ORDER BY name")
    want = sorted(
        (
            i.name,
            i.family,
            i.suds,
            *(t in i.tags for t in ("paper", "survey", "online", "baseline")),
        )
        for i in REGISTRY
    )
    got = [tuple(row) for row in table.itertuples(index=False)]
    assert [(r[0], r[1], *map(bool, r[2:])) for r in got] == want
    assert list(table.columns) == [
        "name",
        "family",
        "suds",
        "paper",
        "survey",
        "online",
        "baseline",
    ]


def test_the_labels_of_every_learner_name_are_as_before(tmp_path):
    """suds / gmr / phase_only of `results_labelled`, read from `learners`, equal migration
    004's name patterns for every registered name and a scikit-learn one."""
    from suds_exp.store import Store
    from suds_exp.testing.synthetic_results import synthetic_results

    store = Store(tmp_path / "x.duckdb")
    names = [i.name for i in REGISTRY] + ["sklearn:Ridge", "sklearn:Ridge+SUDS"]
    rows = synthetic_results("names", n_boot=1, models=names, seed=3)
    with store.write() as conn:
        store.insert_df(conn, "results", rows)
    frame = store.query_df(
        "SELECT DISTINCT model, suds, gmr, phase_only FROM results_labelled ORDER BY model"
    )
    assert sorted(frame.model) == sorted(names)
    for row in frame.itertuples(index=False):
        # the momentum and Finsler learners came after migration 004: SUDS by the table, not the
        # paper's GMR (their own family in the GLM's terms)
        new = row.model in MOMENTUM_LEARNERS + FINSLER_LEARNERS
        assert bool(row.suds) == (SUDS_SUFFIX in row.model if new else row.model.endswith("+SUDS"))
        assert bool(row.gmr) == (row.model.startswith("GMR") and not new), row
        assert bool(row.phase_only) == (row.model == "phase-only"), row


@pytest.mark.parametrize(
    "info", [i for i in REGISTRY if i.builder != ADAPTER], ids=lambda i: i.name
)
def test_the_declared_hyper_parameters_are_the_constructor_and_its_defaults(info):
    cls = builder(info.name)
    declared = {name: p.default for name, p in cls._hyper_parameters.items()}
    assert cls().get_params() == declared
    assert list(inspect.signature(cls).parameters) == list(declared)


def test_a_bad_parameter_is_one_line_naming_it_and_what_was_expected():
    with pytest.raises(ConfigError) as err:
        make_model("GMR+SUDS+P", lag_min_gain=1.0).fit(None)
    assert str(err.value) == "GMR+SUDS+P: lag_min_gain=1.0; expected a number in [0, 1)"
