"""The command layer (`suds_exp.commands`) is Python a user can call: strings in, the
library's values and results out, errors in the CLI's words only through `user_message`."""

from __future__ import annotations

import pytest

from suds_exp.commands.discrepancy import default_out, parse_exclude
from suds_exp.commands.messages import flag, user_message
from suds_exp.commands.simulate import simulate_options, simulate_text
from suds_exp.errors import ConfigError, PreprocessError
from suds_exp.ingest import list_trials
from suds_exp.store import Store


def test_simulate_then_ingest_is_one_call(tmp_path):
    store = Store(tmp_path / "db.duckdb")
    summary = simulate_options(
        tmp_path / "sim", gaits="O", freqs="1", repeats=1, cycles="3", seed=2, store=store
    )
    assert summary["trial_ids"] == [1] and summary["n_trials"] == 1
    assert list_trials(store)[["gait", "frequency_hz"]].values.tolist() == [["O", 1.0]]
    assert simulate_text(summary).endswith("; ingested trials [1]")
    with pytest.raises(ConfigError, match="^use just one of --gaits and --gait-file$"):
        simulate_options(tmp_path / "x", gaits="O", gait_file=tmp_path / "g.toml")


def test_parameters_become_flags_and_steps_commands():
    assert flag("max_effects") == "--max-effects" and flag("params") == "--param"
    assert flag("n_boot", {"n_boot": "--boot"}) == "--boot"
    exc = PreprocessError(
        "trials: no trial with id 9; see the stored trials", param="trials", step="trials"
    )
    assert user_message(exc) == (
        "--trials: no trial with id 9; see the stored trials (`suds-exp trials`)"
    )
    both = PreprocessError("no tables; preprocess first", step=("preprocess", "init"))
    assert user_message(both).endswith("(`suds-exp preprocess` or `suds-exp init`)")
    assert user_message(PreprocessError("plain")) == "plain"


def test_discrepancy_strings():
    assert parse_exclude(None) == () and parse_exclude(" ") == ()
    assert parse_exclude("flippers, servo") == ("flippers", "servo")
    assert default_out("d").as_posix() == "reports/discrepancy-d"
    assert default_out("discrepancy-x").as_posix() == "reports/discrepancy-x"
