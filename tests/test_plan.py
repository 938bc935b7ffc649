"""`plan next` and `plan loop` through the CLI, the library and SQL on a tiny simulated
dataset: recommendations with reasons, the loop's stored iterations and JSON, resuming
after an interruption, and bad input refused with the database left unchanged."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.gait.shape import read_gait_file
from suds_exp.plan import LoopOptions, Target, plan_next, run_loop
from suds_exp.store import Store
from suds_exp.testing.database import assert_same_db, dump_db

runner = CliRunner()


def ok(*args: str) -> str:
    r = runner.invoke(app, list(args))
    assert r.exit_code == 0, r.output + (r.stderr or "")
    return r.stdout


def refused(*args: str) -> str:
    r = runner.invoke(app, list(args))
    assert r.exit_code == 2, r.output
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    return r.stderr


def _preprocessed(work: Path, gaits: str) -> Path:
    """A database of ``gaits`` at 1/2 Hz, one trial of 10 cycles each, ingested and
    preprocessed (version v1)."""
    db = work / "plan.duckdb"
    ok(
        "simulate", "--out", str(work / "d"), "--gaits", gaits, "--freqs", "1/2",
        "--repeats", "1", "--cycles", "10", "--ingest", "--db", str(db), "-q",
    )  # fmt: skip
    ok("preprocess", "--db", str(db), "-q")
    return db


@pytest.fixture(scope="module")
def small(tmp_path_factory) -> Path:
    """O at 1/2 Hz, one trial of 10 cycles, ingested and preprocessed (version v1), and a
    second version (v2) whose shape has four actuated coordinates (cartesian r_a)."""
    db = _preprocessed(tmp_path_factory.mktemp("plan-small"), "O")
    ok("preprocess", "--name", "cart", "--param", "ra_repr=cartesian", "--db", str(db), "-q")
    return db


@pytest.fixture
def db(small, tmp_path) -> Path:
    copy = tmp_path / "db.duckdb"
    shutil.copy(small, copy)
    return copy


def test_next_map_recommends_declared_levels_with_reasons_and_a_stop_signal(db, tmp_path):
    doc = json.loads(
        ok(
            "plan",
            "next",
            "--goal",
            "map",
            "--n",
            "3",
            "--boots",
            "2",
            "--prep",
            "v1",
            "--db",
            str(db),
            "--json",
        )  # fmt: skip
    )
    recs = doc["recommendations"]
    assert len(recs) == 3
    scores = [r["score"] for r in recs]
    assert scores == sorted(scores, reverse=True) and scores[0] > 0
    for r in recs:
        assert r["unit"] == "mm^2" and "prediction variance" in r["reason"]
        assert r["trial"]["cycles"] == 5 and r["trial"]["frequency_hz"] > 0
        assert r["trial"]["gait"] in ("S+", "S-", "O", "D-", "D+")
    # the map goal forecasts the next doubling: from one gait, far from flat
    stop = doc["stop"]
    assert stop["stop"] is False and stop["change_mm"] > stop["spread_mm"]
    assert stop["message"].startswith("continue: the next doubling of cycles")


def test_the_map_criterion_discounts_what_is_recorded_and_spreads_a_batch(small):
    from suds_exp.plan import MapEnsemble
    from suds_exp.plan.recommend import recommend_map
    from suds_exp.preprocess import get_version

    samples = get_version(Store(small), "v1").samples()  # ten cycles of O at 1/2 Hz
    ensemble = MapEnsemble.fit(samples, n_boot=3, seed=0)
    target = Target()

    blind = recommend_map(ensemble, target, 10, n=15)
    seen = recommend_map(ensemble, target, 10, n=15, samples=samples)
    # without the recorded data O is worth recording again; with its ten cycles near the
    # target's paths (and the bias left where they do not reach) another path is worth more
    assert blind[0].score > 0 and "cycles are recorded on average" in seen[0].reason
    assert seen[0].trial.gait.name != "O"
    # a batch: fifteen different trials, each scored as if the ones before were recorded
    picks = [(r.trial.gait.name, r.trial.frequency_hz) for r in seen]
    assert len(set(picks)) == 15
    scores = [r.score for r in seen]
    assert scores == sorted(scores, reverse=True)


def test_next_gait_writes_a_new_gait_file_within_the_bound(db, tmp_path):
    target = Target.of(bound=1.2)
    advice = plan_next(
        Store(db), "v1", "gait", target, out=tmp_path / "next", n_boot=2, max_evals=20
    )
    (rec,) = advice.to_dict()["recommendations"]
    path = Path(rec["trial"]["gait"])
    assert path.is_file() and advice.files == [str(path)]
    assert rec["unit"] == "mm/cycle" and "expected improvement" in rec["reason"]
    assert read_gait_file(path).max_abs() <= 1.2 + 1e-9


@pytest.mark.parametrize(
    "args",
    [
        ("plan", "loop", "--budget-cycles", "0"),
        ("plan", "loop", "--target", "no-such-gait.toml", "--goal", "map"),
        ("plan", "loop", "--bound", "2.5"),
        ("plan", "loop", "--prep", "cart"),
        ("plan", "next", "--prep", "cart"),
        ("plan", "next", "--prep", "v1", "--target", "missing.csv"),
        ("plan", "next", "--prep", "v1", "--goal", "gait", "--bound", "2.5"),
    ],
    ids=["budget", "loop-target", "bound", "body", "next-body", "next-target", "next-bound"],
)
def test_bad_input_is_one_line_and_leaves_the_database_unchanged(db, tmp_path, args):
    before = dump_db(db)
    err = refused(*args, "--out", str(tmp_path / "o"), "--db", str(db))
    assert "error:" in err
    assert_same_db(before, dump_db(db))


def test_bad_input_on_an_empty_folder_creates_no_database(tmp_path):
    db = tmp_path / "none.duckdb"
    refused("plan", "loop", "--budget-cycles", "-5", "--db", str(db))
    assert not db.exists()


def tiny(**kw) -> LoopOptions:
    """A loop small enough for the default suite: two refits, a short gait search."""
    return LoopOptions(**({"n_boot": 2, "max_evals": 20, "cycles": 4} | kw))


def test_a_tiny_loop_stores_its_iterations_and_prints_the_json_layout(tmp_path):
    db = tmp_path / "loop.duckdb"
    doc = json.loads(
        ok(
            "plan",
            "loop",
            "--goal",
            "map",
            "--budget-cycles",
            "10",
            "--seed",
            "3",
            "--out",
            str(tmp_path / "out"),
            "--db",
            str(db),
            "--json",
        )  # fmt: skip
    )
    its = doc["iterations"]
    # warm-up (5 cycles of O at 1/2 Hz) and one planned trial of 5 cycles
    assert [it["cycles_recorded"] for it in its] == [5, 10]
    assert its[0]["trial"] == {"gait": "O", "frequency_hz": 0.5, "cycles": 5}
    for it in its:
        assert set(it["trial"]) == {"gait", "frequency_hz", "cycles"}
        assert set(it["best_gait"]) >= {"phase_rad", "phi1_rad", "phi2_rad"}
        for key in ("cycles_total", "predicted_forward_mm", "achieved_forward_mm", "map_error"):
            assert np.isfinite(it[key])
        assert it["reason"]
    assert its[1]["cycles_total"] >= its[0]["cycles_total"] + 4
    assert set(doc["stop"]) >= {"stop", "reason"}
    stored = Store(db).query_df(
        "SELECT * FROM plan_iterations WHERE loop_id = ? ORDER BY iteration", [doc["loop_id"]]
    )
    assert stored["cycles_recorded"].tolist() == [5, 10]
    np.testing.assert_allclose(stored["map_error_mm"], [it["map_error"] for it in its], atol=1e-3)
    assert stored["trial_id"].notna().all()
    # the planned trial is data like any other: ingested and in the (only) version
    n = Store(db).query_df("SELECT count(*) AS n FROM prep_trials")["n"].iloc[0]
    assert n == 2


@pytest.fixture(scope="module")
def gait_loop(tmp_path_factory) -> tuple[Path, object]:
    """A tiny gait-goal loop from an empty database: warm-up and one designed gait."""
    work = tmp_path_factory.mktemp("plan-gait")
    db = work / "g.duckdb"
    loop = run_loop(Store(db), tiny(goal="gait", budget_cycles=9, bound=1.2), out=work / "o")
    return db, loop


def test_the_gait_goal_records_designed_gaits_within_the_bound(gait_loop):
    db, loop = gait_loop
    first, planned = loop.iterations
    assert planned.trial["gait"].endswith("-it1.toml") and planned.cycles_recorded == 9
    assert "expected improvement" in planned.reason
    assert np.abs(planned.best_gait.cycle()[1]).max() <= 1.2 + 1e-9
    assert planned.achieved_forward_mm > 0 and first.trust_radius > 0
    gaits = Store(db).query_df("SELECT gait FROM trials ORDER BY id")["gait"].tolist()
    assert gaits == ["O", planned.trial["gait"]]


def test_the_gait_goal_s_best_gait_is_the_one_that_went_furthest_in_its_trials(gait_loop):
    from suds_exp.plan.loop import measured_forward
    from suds_exp.preprocess import get_version

    db, loop = gait_loop
    measured = measured_forward(get_version(Store(db)).samples(), 0.5)
    assert set(measured) == {"O", loop.iterations[1].trial["gait"]}
    furthest = max(measured, key=measured.get)
    assert loop.iterations[-1].best_gait.name == furthest, measured
    # O's forward motion per cycle as recorded (the simulator's 24.3 mm, less the
    # actuator's lag)
    assert 15.0 < measured["O"] < 30.0


def test_the_best_gait_follows_the_recording_not_the_map(tmp_path, monkeypatch):
    # a tiny loop's map ranks the warm-up's O above its one designed gait; a recording
    # in which the designed gait went furthest makes it the best gait all the same
    import suds_exp.plan.loop as loop_module

    def designed_furthest(samples, frequency_hz):
        return {g: 1e3 for g in set(samples["gait"]) if g != "O"}

    monkeypatch.setattr(loop_module, "measured_forward", designed_furthest)
    loop = run_loop(
        Store(tmp_path / "g.duckdb"), tiny(goal="gait", budget_cycles=9, bound=1.2),
        out=tmp_path / "o",
    )  # fmt: skip
    assert loop.iterations[1].best_gait.name == loop.iterations[1].trial["gait"]


def test_an_interrupted_loop_keeps_what_was_stored_and_continues(tmp_path, monkeypatch):
    import suds_exp.plan.loop as loop_module

    store = Store(tmp_path / "r.duckdb")
    out = tmp_path / "o"
    opts = tiny(goal="map", budget_cycles=13, seed=5)
    store_iteration = loop_module._store_iteration

    def killed_before_storing_iteration_2(st, loop_id, it):
        # the worst moment: iteration 2's trial is recorded and preprocessed, its row not
        if it.iteration == 2:
            raise KeyboardInterrupt
        store_iteration(st, loop_id, it)

    monkeypatch.setattr(loop_module, "_store_iteration", killed_before_storing_iteration_2)
    with pytest.raises(KeyboardInterrupt):
        run_loop(store, opts, out=out)
    kept = store.query_df("SELECT iteration, trial_id FROM plan_iterations ORDER BY 1")
    assert kept["iteration"].tolist() == [0, 1]
    n_trials = store.query_df("SELECT count(*) AS n FROM trials")["n"].iloc[0]
    assert n_trials == 3
    monkeypatch.setattr(loop_module, "_store_iteration", store_iteration)
    loop = run_loop(store, opts, out=out)
    rows = store.query_df("SELECT iteration, trial_id FROM plan_iterations ORDER BY 1")
    assert rows["iteration"].tolist() == [0, 1, 2]
    assert rows["trial_id"].iloc[:2].tolist() == kept["trial_id"].tolist()
    assert [it.cycles_recorded for it in loop.iterations] == [5, 9, 13]
    # the trial recorded before the interruption is the one iteration 2 stores: no new one
    assert store.query_df("SELECT count(*) AS n FROM trials")["n"].iloc[0] == n_trials
    assert (
        rows["trial_id"].iloc[2] == store.query_df("SELECT max(id) AS m FROM trials")["m"].iloc[0]
    )
    # one loop, found again by its name; run once more with its budget spent: no change
    assert store.query_df("SELECT count(*) AS n FROM plan_loops")["n"].iloc[0] == 1
    before = dump_db(store.path)
    run_loop(store, opts, out=out)
    assert_same_db(before, dump_db(store.path))


def test_run_report_and_findings_work_on_the_version_after_a_gait_loop(gait_loop, tmp_path):
    db = tmp_path / "run.duckdb"
    shutil.copy(gait_loop[0], db)
    # the loop's gait files are added levels of the stored design
    store = Store(db)
    added = store.query_df("SELECT level FROM experiment_levels WHERE added_by LIKE 'plan loop%'")
    assert len(added) >= 1
    # the warm-up (one short trial of O at 1/2 Hz) and the designed gait's trial cannot
    # form a same-condition pair; the loop chose and recorded both, so a plain run
    # leaves those cells out and says so, as it does for any added level
    args = ("--models", "GMR", "--boots", "1", "--train-cycles", "3", "--db", str(db))
    out = ok("run", "after", *args, "-q")
    assert "left out:" in out and "O@0.5" in out
    ok("report", "after", "--out", str(tmp_path / "report"), "--db", str(db))
    ok("findings", "after", "--db", str(db))


def test_run_after_a_map_loop_leaves_out_only_what_the_loop_recorded(tmp_path):
    db = tmp_path / "m.duckdb"
    run_loop(Store(db), tiny(goal="map", budget_cycles=13, seed=2), out=tmp_path / "o")
    with Store(db).write() as conn:
        marked = conn.exec_driver_sql(
            "SELECT count(*) = (SELECT count(*) FROM trials) FROM trials_added "
            "WHERE added_by LIKE 'plan loop plan-%'"
        ).scalar()
        assert marked  # every trial the loop recorded, its warm-up included
        # the campaign knows the loop's trials from the data alone, not from plan tables
        conn.exec_driver_sql("DROP TABLE plan_iterations")
    args = ("--models", "GMR", "--boots", "1", "--train-cycles", "3", "--db", str(db))
    out = ok("run", "m", *args, "-q")
    assert "left out:" in out
    # a declared condition the user recorded is not excused: one short trial of S+ of
    # the user's own is refused as before, naming --skip-infeasible
    ok(
        "simulate", "--out", str(tmp_path / "d"), "--gaits", "S+", "--freqs", "1",
        "--repeats", "1", "--cycles", "4", "--ingest", "--db", str(db), "-q",
    )  # fmt: skip
    # into the loop's version, which gives the simulated robot's motor-axis distance
    ok("preprocess", "--db", str(db), "--param", "joint_distance_mm=100", "-q")
    r = runner.invoke(app, ["run", "m2", *args])
    assert r.exit_code != 0 and "skip-infeasible" in r.stderr


@pytest.fixture(scope="module")
def three_paths(tmp_path_factory) -> Path:
    """O, D- and S- at 1/2 Hz, one trial of 10 cycles each, preprocessed (version v1)."""
    return _preprocessed(tmp_path_factory.mktemp("plan-three"), "O,D-,S-")


def test_the_map_criterion_prefers_a_path_no_data_covers(three_paths):
    from suds_exp.plan import MapEnsemble
    from suds_exp.plan.recommend import bias_variance, recommend_map
    from suds_exp.preprocess import get_version

    samples = get_version(Store(three_paths), "v1").samples()
    ensemble = MapEnsemble.fit(samples, n_boot=3, seed=0)
    target = Target()
    # the bootstrap sees the noise of the three recorded paths, not the map's bias between
    # them: the path jackknife (the target predicted by maps each fitted without one
    # recorded path) is what makes a path not yet recorded worth recording
    bias = bias_variance(samples, target)
    assert bias.shape == (5,) and np.all(bias > 0)
    (first,) = recommend_map(ensemble, target, 10, samples=samples)
    assert first.trial.gait.name in ("D+", "S+"), first.reason
    assert "bias between paths" in first.reason
    batch = recommend_map(ensemble, target, 10, n=2, samples=samples)
    assert {r.trial.gait.name for r in batch} == {"D+", "S+"}


def test_the_stopping_signal_needs_two_verdicts_and_does_not_flicker():
    from suds_exp.plan.curve import StopSignal, latched

    def verdict(stop: bool) -> StopSignal:
        return StopSignal(stop, "stop: x" if stop else "continue: x", [8.0, 16.0], [], [], None)

    said, before, fired = [], None, False
    for stop in (True, False, True, True, False, True):
        signal = latched(verdict(stop), before, fired)
        before, fired = verdict(stop), fired or signal.stop
        said.append(signal.stop)
    assert said == [False, False, False, True, True, True]


def test_a_recorded_path_at_one_third_hz_is_known_as_recorded():
    import pandas as pd

    from suds_exp.plan.recommend import declared_levels, recorded_paths

    # stored frequencies have 6 decimals; the declared level is 1/3 exactly
    frame = pd.DataFrame({"gait": ["O", "O", "D-"], "frequency_hz": [0.333333, 0.333333, 0.5]})
    paths = recorded_paths(frame)
    assert paths == [("D-", 0.5), ("O", 0.333333)]
    levels = {(g.name, round(f, 6)) for g, f in declared_levels()}
    assert set(paths) <= levels


def test_the_map_stopping_signal_forecasts_the_next_doubling(small, three_paths):
    from suds_exp.plan import MapEnsemble, forecast_signal
    from suds_exp.plan.recommend import recommend_map
    from suds_exp.preprocess import get_version

    target = Target()
    verdicts = {}
    for name, db in (("one path", small), ("three paths", three_paths)):
        samples = get_version(Store(db), "v1").samples()
        ensemble = MapEnsemble.fit(samples, n_boot=3, seed=0)
        signal = forecast_signal(samples, ensemble, target, 10)
        # the doubling is spent on the trials the planner would choose: as many trials
        # of 10 cycles as cycles are recorded, over 10
        n = signal.cycles[0]
        trials = recommend_map(ensemble, target, 10, max(1, round(n / 10)), samples)
        assert signal.cycles == [n, n + 10 * len(trials)]
        assert signal.stop == (signal.change_mm < signal.spread_mm)
        assert signal.message.startswith("stop: " if signal.stop else "continue: ")
        verdicts[name] = signal
    # a map that has seen one gait errs elsewhere by the order of the motion itself, and a
    # second path removes much of that: never a reason to stop
    one, three = verdicts["one path"], verdicts["three paths"]
    assert not one.stop, one.message
    assert three.change_mm < one.change_mm
    # calibrated by the last doubling once its first half holds two paths (O, D-), not
    # on one path, whose model error is a prior
    assert "of its variance now is removable" in three.message
    assert "removable" not in one.message


def test_a_loop_from_an_empty_database_knows_the_robots_motor_axis_distance(gait_loop):
    # a warm-up of one gait (O) leaves the fitted distance biased by about 3 mm
    db, _ = gait_loop
    row = Store(db).query_df(
        "SELECT v.params, f.state FROM prep_versions v JOIN prep_fits f "
        "ON f.version_id = v.id AND f.kind = 'joints'"
    )
    assert json.loads(row.params.iloc[0])["joint_distance_mm"] == 100.0
    assert json.loads(row.state.iloc[0])["length_mm"] == 100.0


def test_the_gait_goal_looks_beyond_a_trust_region_that_leaves_no_resolvable_step(small):
    # A trust region too small for any step the map can tell from standing still is a
    # converged local search: the planner then looks over the whole bound, where the
    # refits' spread away from the data earns exploration, and says so.
    from suds_exp.gait.shape import NamedGait
    from suds_exp.gait.support import Support
    from suds_exp.plan import MapEnsemble
    from suds_exp.plan.recommend import expected_improvement, recommend_gait
    from suds_exp.preprocess import get_version

    samples = get_version(Store(small), "v1").samples()
    ensemble = MapEnsemble.fit(samples, n_boot=3, seed=0)
    support = Support.of(samples)
    target = Target.of(bound=1.2)
    trust = 0.001
    # order 1: O traced twice a cycle would be a resolvable step on O's own path
    rec, best, best_value = recommend_gait(
        ensemble, support, [NamedGait("O")], target, trust, 5, "next.toml", order=1,
        max_evals=30,
    )  # fmt: skip
    assert best.name == "O"
    gait = rec.trial.gait
    assert support.gait_distance(gait) > 10 * trust, rec.reason
    assert "beyond the trust radius" in rec.reason
    assert gait.max_abs() <= 1.2 + 1e-9
    # what it reports is what the map says of the gait it recommends
    mean, sd = ensemble.forward(gait, 0.5)
    assert rec.score == pytest.approx(expected_improvement(mean, sd, best_value))
    assert rec.score > expected_improvement(best_value, 0.0, best_value)


def test_the_gait_goal_considers_a_loop_traced_twice_a_cycle(small):
    # A principally kinematic body moves as far per loop however fast it traces it, so
    # within an order-2 Fourier family the loop traced twice a cycle moves about twice
    # as far per cycle. The learned map knows (GMR's map is homogeneous in the shape
    # velocity); the search has to look there too, or its best gait is a local optimum.
    from suds_exp.gait.shape import NamedGait
    from suds_exp.gait.support import Support
    from suds_exp.plan import MapEnsemble
    from suds_exp.plan.recommend import recommend_gait
    from suds_exp.preprocess import get_version

    samples = get_version(Store(small), "v1").samples()
    ensemble = MapEnsemble.fit(samples, n_boot=3, seed=0)
    support = Support.of(samples)
    rec, _, best_value = recommend_gait(
        ensemble, support, [NamedGait("O")], Target.of(bound=1.2), 1.0, 5, "next.toml",
        max_evals=40,
    )  # fmt: skip
    gait = rec.trial.gait
    energy = (gait.a**2 + gait.b**2).sum(axis=1)
    assert energy[1] > energy[0], (gait.a, gait.b)
    assert rec.predicted_forward_mm > 1.5 * best_value, rec.reason
    assert gait.max_abs() <= 1.2 + 1e-9


def test_the_gait_goal_s_spread_counts_the_bias_between_recorded_paths(three_paths, small):
    # The cycle bootstrap sees the noise of what is recorded, not how much a new gait's
    # prediction depends on which gaits were recorded; the gait goal's planned trials
    # missed their predictions by several bootstrap spreads. Its spread adds the path
    # jackknife's variance (each recorded gait and frequency left out in turn).
    from suds_exp.gait.design import circle
    from suds_exp.gait.predict import fit_map
    from suds_exp.plan import MapEnsemble
    from suds_exp.preprocess import get_version

    samples = get_version(Store(three_paths), "v1").samples()
    gait = circle(1.0, 2, lag=0.6)  # no trial ran it
    boot = MapEnsemble.fit(samples, n_boot=3, seed=0)
    both = MapEnsemble.fit(samples, n_boot=3, seed=0, paths=True)
    mean, boot_sd = boot.forward(gait, 0.5)
    mean_both, sd = both.forward(gait, 0.5)
    assert mean_both == mean and boot_sd > 0
    labels = samples["gait"].astype(str)
    held = np.array([fit_map(samples[labels != g]).forward(gait, 0.5) for g in ("D-", "O", "S-")])
    jackknife = 2 / 3 * np.sum((held - held.mean()) ** 2)
    assert sd == pytest.approx(np.sqrt(boot_sd**2 + jackknife), rel=1e-9)
    assert sd > boot_sd
    # one recorded path: nothing to leave out, the spread is the bootstrap's
    one = get_version(Store(small), "v1").samples()
    alone = MapEnsemble.fit(one, n_boot=3, seed=0, paths=True)
    assert alone.paths == []
    assert alone.forward(gait, 0.5) == MapEnsemble.fit(one, n_boot=3, seed=0).forward(gait, 0.5)


def test_plan_next_s_gait_spread_counts_the_paths(three_paths, tmp_path, monkeypatch):
    # what `plan next --goal gait` plans with and reports is the spread with the paths
    from suds_exp.plan import MapEnsemble

    fits = []
    real = MapEnsemble.fit.__func__

    def spy(cls, *args, **kw):
        fits.append(kw.get("paths", args[4] if len(args) > 4 else False))
        return real(cls, *args, **kw)

    monkeypatch.setattr(MapEnsemble, "fit", classmethod(spy))
    copy = tmp_path / "db.duckdb"
    copy.write_bytes(Path(three_paths).read_bytes())
    advice = plan_next(Store(copy), "v1", "gait", Target.of(bound=1.2), out=tmp_path / "n",
                       n_boot=2, max_evals=10)  # fmt: skip
    assert fits == [True]
    (rec,) = advice.recommendations
    assert rec.spread_mm > 0


def test_the_stopping_signals_count_recorded_cycles_not_the_phasers_loops(small, three_paths):
    from suds_exp.plan import MapEnsemble, forecast_signal, learning_curve, plan_next
    from suds_exp.preprocess import get_version

    store = Store(three_paths)
    samples = get_version(store, "v1").samples()
    recorded = plan_next(store, "v1", goal="map", n=1, cycles=10).cycles_total
    assert recorded == 30  # three trials of 10 cycles
    # the doubling is of the cycles the user recorded, whatever the phaser counts (it
    # also counts the part cycles at each trial's ends)
    signal = forecast_signal(samples, MapEnsemble.fit(samples, n_boot=3, seed=0), Target(), 10)
    assert signal.cycles[0] == recorded
    assert f"({recorded} -> " in signal.message
    # a gait that runs its loop twice a cycle gives the phaser two loops a cycle: the
    # learning curve's training sizes are still cycles recorded, at most all of them
    one = get_version(Store(small), "v1").samples()
    looped = one.assign(cycle=np.floor(2 * one["phase"] / (2 * np.pi)).astype(int))
    assert looped["cycle"].nunique() > 1.8 * one["cycle"].nunique()
    for frame in (one, looped):
        curve = learning_curve(frame)
        assert curve.cycles[-1] <= 10 and curve.cycles[-1] == pytest.approx(
            2 * curve.cycles[0], rel=0.2
        ), curve.message
        assert "of the 10 recorded" in curve.message, curve.message
    # a trial of unknown frequency can only count the phaser's cycle blocks
    from suds_exp.plan.ensemble import count_cycles

    assert count_cycles(one.assign(frequency_hz=None)) == one["cycle"].nunique()


def test_plan_next_compares_with_every_recorded_gait_wherever_its_out_is(gait_loop, tmp_path):
    db, loop = gait_loop
    copy = tmp_path / "g.duckdb"
    shutil.copy(db, copy)
    designed = loop.iterations[1].trial["gait"]
    # a loop records each gait file beside its capture: plan next finds it there, not
    # only in its own --out folder
    doc = json.loads(
        ok("plan", "next", "--goal", "gait", "--bound", "1.2", "--out", str(tmp_path / "x"),
           "--boots", "2", "--db", str(copy), "--json")
    )  # fmt: skip
    assert doc["recorded_gaits"] == sorted(["O", designed]) and doc["notes"] == []
    # a gait file found nowhere is named, not silently left out of "the best recorded gait"
    with Store(copy).write() as conn:
        conn.exec_driver_sql("UPDATE trials SET gait = 'lost.toml' WHERE gait = ?", (designed,))
    printed = ok("plan", "next", "--goal", "gait", "--bound", "1.2", "--out",
                 str(tmp_path / "x"), "--boots", "2", "--db", str(copy))  # fmt: skip
    assert f"note: recorded gait file(s) not found in {tmp_path / 'x'}" in printed
    assert printed.split("note:", 1)[1].splitlines()[0].endswith("compared with: lost.toml")


def test_the_map_criterion_counts_recorded_cycles_not_the_phasers_loops(small):
    from suds_exp.plan.recommend import recorded_cycles_near
    from suds_exp.preprocess import get_version

    one = get_version(Store(small), "v1").samples()
    looped = one.assign(cycle=np.floor(2 * one["phase"] / (2 * np.pi)).astype(int))
    near = recorded_cycles_near(one, Target())
    np.testing.assert_allclose(recorded_cycles_near(looped, Target()), near)
    # ten cycles recorded: no target sample is near more of them
    assert near.max() <= 10.0 + 1e-9
