"""The paper's last two questions, measured: momentum (body_inertia.tau_s) and Finsler
contact (asymmetric_drag.ratio) against the learners, by the paper's protocol.

Usage (from the repository root)::

    OMP_NUM_THREADS=1 .venv/bin/python -m benchmarks.studies.momentum --out /tmp/momentum
        [--taus 0,0.1,0.25,0.5] [--ratios 1,1.5,2.5] [--boots 6] [--train-cycles 4]
    OMP_NUM_THREADS=1 .venv/bin/python -m benchmarks.studies.momentum --out /tmp/x --why-tau 0.3
        [--prep-param joint_distance_mm=100]
    OMP_NUM_THREADS=1 .venv/bin/python -m benchmarks.studies.momentum --out /tmp/x --synthetic
    OMP_NUM_THREADS=1 .venv/bin/python -m benchmarks.studies.momentum --out /tmp/x \
        --snake ../shared/refdata

For each value: `suds-exp simulate` (gait O at 1/3, 1/2 and 1 Hz, 2 trials of 12-16
cycles each, the effect set, the rest nominal) with --ingest, `preprocess`, and a
campaign (`run`) on every (train, test) frequency pair of O with `--boots` draws and
`--train-cycles` training cycles. tau_s: GMR, GMR+SUDS, GMR+P, GMR+SUDS+P, then GMR+P
with the time constant `momentum_information` estimates on the version's samples (its
held-out tau: the one lag that best predicts each held-out frequency; a campaign's
training set holds one frequency, which cannot tell a lag from another map) in a second
campaign beside GMR, "GMR+P (held-out tau)", whose ratio is to that campaign's GMR (the
same draws). ratio: phase-only, TLS, TLS+F, GMR, GMR+F.

Printed per value: median held-out RMSE of vx, vy (mm/s), wz (rad/s) per learner,
same- and different-frequency pairs apart, each with a 95% bootstrap interval of the
median over draws; then, on different-frequency pairs, each learner's ratio of median
vx errors to GMR's with its interval (draws resampled in pairs). Also printed: the
momentum diagnostic's time constants and verdict.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks._harness import ROOT, script_parser
from suds_exp.analysis.formatting import to_markdown

N_BOOT = 2000


def cli(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "suds_exp", *args, "-q"], check=True, env=os.environ)


#: ``--prep-param`` values, passed to every `preprocess` as ``--param``
PREP_PARAMS: list[str] = []


def dataset(out: Path, effect: str) -> Path:
    name = effect.replace("=", "-").replace(".", "_")
    folder, db = out / name, out / f"{name}.duckdb"
    if not db.exists():
        cli("simulate", "--out", str(folder), "--gaits", "O", "--repeats", "2", "--cycles",
            "12:16", "--effect", effect, "--ingest", "--db", str(db))  # fmt: skip
        cli("preprocess", "--db", str(db), *[a for v in PREP_PARAMS for a in ("--param", v)])
    return db


def campaign(db: Path, name: str, models: str, args, *extra: str) -> pd.DataFrame:
    cli("run", name, "--db", str(db), "--models", models, "--boots", str(args.boots),
        "--train-cycles", str(args.train_cycles), "--train-conditions", "O",
        "--test-conditions", "O", *extra)  # fmt: skip
    from suds_exp.store import Store

    return Store(db).query_df(
        "SELECT model, train_frequency_hz, test_frequency_hz, boot, rmse_vx, rmse_vy, "
        "rmse_wz, error FROM results WHERE campaign = ?",
        [name],
    )


def interval(values: np.ndarray, rng) -> tuple[float, float, float]:
    idx = rng.integers(0, len(values), size=(N_BOOT, len(values)))
    lo, hi = np.percentile(np.median(values[idx], axis=1), [2.5, 97.5])
    return float(np.median(values)), float(lo), float(hi)


def summary(results: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    rng = np.random.default_rng(0)
    r = results.assign(
        pairs=np.where(
            results.train_frequency_hz.round(6) == results.test_frequency_hz.round(6),
            "same",
            "different",
        )
    )
    rows = []
    for (pairs, model), g in r.groupby(["pairs", "model"], sort=False):
        row = {"pairs": pairs, "learner": model, "draws": len(g)}
        for c, digits in (("rmse_vx", 2), ("rmse_vy", 2), ("rmse_wz", 3)):
            m, lo, hi = interval(g[c].to_numpy(dtype=float), rng)
            row[c[5:]] = f"{m:.{digits}f} [{lo:.{digits}f}, {hi:.{digits}f}]"
        rows.append(row)
    table = pd.DataFrame(rows).sort_values(["pairs", "learner"], ascending=[False, True])
    diff = r[r.pairs == "different"].pivot_table(
        index=["train_frequency_hz", "test_frequency_hz", "boot"], columns="model", values="rmse_vx"
    )
    ratios = []
    for model in diff.columns:
        if model == "GMR":
            continue
        a, b = diff[model].to_numpy(), diff["GMR"].to_numpy()
        idx = rng.integers(0, len(a), size=(N_BOOT, len(a)))
        boot = np.median(a[idx], axis=1) / np.median(b[idx], axis=1)
        lo, hi = np.percentile(boot, [2.5, 97.5])
        ratios.append(
            {
                "learner": model,
                "vx ratio to GMR": f"{np.median(a) / np.median(b):.2f}",
                "95% interval": f"[{lo:.2f}, {hi:.2f}]",
            }  # fmt: skip
        )
    return table, pd.DataFrame(ratios)


def diagnostic(db: Path) -> pd.DataFrame:
    from suds_exp.analysis.momentum_info import momentum_display, momentum_information
    from suds_exp.preprocess import get_version
    from suds_exp.store import Store

    store = Store(db)
    samples = get_version(store, "v1").samples()
    freq = store.query_df("SELECT id, frequency_hz FROM trials").set_index("id")["frequency_hz"]
    return momentum_display(momentum_information(samples, freq))


def synthetic_finsler() -> None:
    """The learners on the synthetic swimmer with a known asymmetric map
    (velocity="asymmetric", ratio 1 and 2.5): RMS error of (vx, vy) against the noise-free
    velocity. Two training sets of 20 cycles of O at 1/2 Hz: "forwards" (2 trials of 10
    cycles), where each shape is passed with one sign of its shape velocity, and "both
    ways" (10 cycles forwards, 10 backwards), where the two halves of the map both show;
    tested on 5 cycles a trial of O at 1/2 and 1 Hz and D+ at 1/2 Hz, run the same
    ways. "TLS+F linear" is TLS+F with split=False (its linear twin). Then TLS's
    prediction against the truth at other frequencies (least-squares slope; 0.5 / f if
    TLS predicts the training speed's velocity)."""
    from suds_exp.models import make_model
    from suds_exp.testing.synthetic_swimmer import make_samples

    def swimmer(ratio, n, gait, f, seed, first, ways="forwards"):
        kw = dict(gait=gait, frequency_hz=f, passive="none", velocity="asymmetric",
                  asymmetry=ratio)  # fmt: skip
        if ways == "forwards":
            return make_samples(n, n_trials=2, seed=seed, first_trial_id=first, **kw)
        return pd.concat([make_samples(n, seed=seed, first_trial_id=first, **kw),
                          make_samples(n, seed=seed + 1, first_trial_id=first + 1,
                                       direction=-1, **kw)], ignore_index=True)  # fmt: skip

    learners = {"GMR": ("GMR", {}), "GMR+F": ("GMR+F", {}), "TLS": ("TLS", {}),
                "TLS+F": ("TLS+F", {}), "TLS+F linear": ("TLS+F", {"split": False})}  # fmt: skip
    rows, slopes = [], []
    for ways in ("forwards", "both ways"):
        for ratio in (1.0, 2.5):
            train = swimmer(ratio, 10, "O", 0.5, 1, 1, ways)
            for gait, f in (("O", 0.5), ("O", 1.0), ("D+", 0.5)):
                test = swimmer(ratio, 5, gait, f, 7, 10, ways)
                truth = test[["vx_true", "vy_true"]].to_numpy()
                row = {"data": ways, "ratio": ratio, "test": f"{gait} at {f:g} Hz"}
                err = {}
                for label, (name, params) in learners.items():
                    model = make_model(name, **params).fit(train)
                    pred = model.predict(test)[["vx", "vy"]].to_numpy()
                    err[label] = float(np.sqrt(np.mean((pred - truth) ** 2)))
                    row[label] = f"{err[label]:.2f}"
                row["GMR+F / GMR"] = f"{err['GMR+F'] / err['GMR']:.2f}"
                row["TLS+F / TLS"] = f"{err['TLS+F'] / err['TLS']:.2f}"
                row["TLS+F / linear"] = f"{err['TLS+F'] / err['TLS+F linear']:.2f}"
                rows.append(row)
            if ways == "forwards":
                tls = make_model("TLS").fit(train)
                for f in (1 / 3, 1.0):
                    test = swimmer(ratio, 5, "O", f, 7, 10)
                    t, q = test["vx_true"].to_numpy(), tls.predict(test)["vx"].to_numpy()
                    slopes.append({"ratio": ratio, "test Hz": f"{f:.3g}",
                                   "slope of TLS's vx on the truth": f"{q @ t / (t @ t):.3f}",
                                   "training / test speed": f"{0.5 / f:.3f}"})  # fmt: skip
    print("\n## synthetic Finsler swimmer (RMS error of vx, vy, mm/s)\n")
    print(to_markdown(pd.DataFrame(rows)) + "\n\n" + to_markdown(pd.DataFrame(slopes)))


def flying_snake(refdata: Path) -> None:
    """The real flying-snake glide of docs/results/flying-snake.md, GMR against GMR+P:
    fitted on the first 70 % of the glide, tested on the rest; and GMR+P's time
    constants fitted on the training part."""
    import tempfile

    from suds_exp.body.real_snake import holdout_errors, run_real_snake
    from suds_exp.models import make_model
    from suds_exp.preprocess import get_version
    from suds_exp.store import Store

    capture = refdata / "flying_snake_qualisys" / "413_91.tsv"
    body = ROOT / "examples" / "flying_snake.toml"
    with tempfile.TemporaryDirectory() as tmp:
        db = Path(tmp) / "snake.duckdb"
        out = run_real_snake([capture], body, db)
        samples = get_version(Store(db), out["version"]).samples()
    print("\n## flying snake (RMS error, % of the test RMS)\n")
    print(to_markdown(holdout_errors(samples, models=("GMR", "GMR+P")), 1))
    train = samples.iloc[: int(0.7 * len(samples))]
    print("\nGMR+P tau_ (s):", np.round(make_model("GMR+P").fit(train).tau_, 3))


def why_tau(out: Path, tau: str) -> None:
    """Where GMR+P's time constants go wrong on the simulator (body_inertia.tau_s=tau):
    fitted on cycles 2-5 of every trial (about 50 samples a cycle, as
    `momentum_information` takes them) pooled and per frequency, on the preprocessed
    velocity and on the simulator's own (``*.truth.parquet``, interpolated to the samples'
    times); then how much of (preprocessed - simulator) velocity an instantaneous map
    linear in dr_a/dt (coefficients affine in r_a) explains."""
    from suds_exp.models import make_model
    from suds_exp.store import Store

    db = dataset(out, f"body_inertia.tau_s={tau}")
    folder = out / db.stem
    s = (
        Store(db)
        .query_df(
            "SELECT s.*, tr.frequency_hz, tr.source_file FROM samples s "
            "JOIN trials tr ON tr.id = s.trial_id ORDER BY s.trial_id, s.t"
        )
        .dropna(axis=1, how="all")
    )
    parts = []
    for (_, source), g in s.groupby(["trial_id", "source_file"]):
        truth = pd.read_parquet(folder / Path(source).name.replace(".tsv", ".truth.parquet"))
        parts.append(g.assign(**{f"{c}_sim": np.interp(g["t"], truth["t"], truth[c])
                                 for c in ("vx", "vy", "wz")}))  # fmt: skip
    s = pd.concat(parts)
    first = s.groupby("trial_id")["cycle"].transform("min")
    s = s[(s["cycle"] >= first + 1) & (s["cycle"] < first + 5)]
    per_cycle = s.groupby("trial_id")["t"].transform("size") / 4
    s = s[(s.groupby("trial_id").cumcount() % np.maximum(1, np.round(per_cycle / 50))) == 0]
    sim = s.assign(vx=s["vx_sim"], vy=s["vy_sim"], wz=s["wz_sim"])
    rows = []
    for label, data in (("preprocessed", s), ("simulator's", sim)):
        for f, g in [("all", data), *data.groupby("frequency_hz")]:
            tau_ = make_model("GMR+P").fit(g).tau_
            rows.append({"velocity": label, "trained on (Hz)": f if f == "all" else f"{f:.3g}",
                         "tau vx, vy, wz (s)": ", ".join(f"{v:.3f}" for v in tau_)})  # fmt: skip
    print(f"\n## GMR+P's time constants at tau_s = {tau} s\n")
    print(to_markdown(pd.DataFrame(rows)))
    ra, dra = s[["ra_1", "ra_2"]].to_numpy(), s[["dra_1", "dra_2"]].to_numpy()
    X = np.column_stack([dra, (ra[:, :, None] * dra[:, None, :]).reshape(len(s), 4),
                         np.ones(len(s))])  # fmt: skip
    rows = []
    for c in ("vx", "vy", "wz"):
        e = (s[c] - s[f"{c}_sim"]).to_numpy()
        b = np.linalg.lstsq(X, e, rcond=None)[0]
        share = 1 - np.var(e - X @ b) / np.var(e)
        rows.append({"component": c, "RMS of the difference": f"{e.std():.3f}",
                     "explained by an instantaneous map": f"{share:.2f}"})  # fmt: skip
    print("\n" + to_markdown(pd.DataFrame(rows)))
    print("\n" + to_markdown(tau_profile(db)))


def tau_profile(db: Path) -> pd.DataFrame:
    """GMR+P with one time constant on vx, vy and wz, over a grid of them, on the samples
    `momentum_information` takes: in-sample RMSE (fitted on every frequency) and the
    median over frequencies of the RMSE on each held-out frequency (fitted on the others);
    vx, vy in mm/s, wz in rad/s."""
    from suds_exp.analysis.momentum_info import COMPONENTS, _windows, heldout_errors
    from suds_exp.models import make_model
    from suds_exp.preprocess import get_version
    from suds_exp.store import Store

    store = Store(db)
    s = get_version(store, "v1").samples()
    freq = store.query_df("SELECT id, frequency_hz FROM trials").set_index("id")["frequency_hz"]
    data = _windows(s.assign(_f=s["trial_id"].map(freq).round(6).to_numpy()), 4, 50, 6)
    levels = sorted(data["_f"].unique())
    rows = []
    for tau in (0.0, 0.1, 0.2, 0.25, 0.3, 0.35, 0.4, 0.5, 0.6, 0.8):
        pred = make_model("GMR+P", tau=tau).fit(data).predict(data)
        inside = [np.sqrt(np.mean((pred[c] - data[c]) ** 2)) for c in COMPONENTS]
        held = heldout_errors(data, levels, tau)
        rows.append(
            {
                "tau (s)": f"{tau:.2f}",
                "in-sample vx, vy, wz": ", ".join(f"{v:.3f}" for v in inside),
                "held-out frequency vx, vy, wz": ", ".join(f"{v:.3f}" for v in held),
            }
        )
    return pd.DataFrame(rows)


def main(argv=None) -> None:
    ap = script_parser(__doc__.split("\n\n")[0], "a smoke run: tau 0, one draw")
    ap.add_argument("--out", type=Path, help="the databases' folder (required unless --quick)")
    ap.add_argument("--taus", default="0,0.1,0.25,0.5")
    ap.add_argument("--ratios", default="1,1.5,2.5")
    ap.add_argument("--boots", type=int, default=6)
    ap.add_argument("--train-cycles", type=int, default=4)
    ap.add_argument("--synthetic", action="store_true", help="the synthetic Finsler swimmer")
    ap.add_argument("--snake", type=Path, help="refdata folder: the flying snake, GMR vs GMR+P")
    ap.add_argument("--why-tau", metavar="TAU", help="GMR+P's time constants against the truth")
    ap.add_argument("--prep-param", action="append", default=[], metavar="KEY=VALUE",
                    help="a preprocessing parameter for every dataset (repeatable)")  # fmt: skip
    args = ap.parse_args(argv)
    PREP_PARAMS[:] = args.prep_param
    if args.quick:
        with tempfile.TemporaryDirectory(prefix="suds-momentum-quick-") as tmp:
            args.out, args.taus, args.ratios, args.boots = Path(tmp), "0", "", 1
            study(args)
        return
    if args.out is None and not (args.synthetic or args.snake):
        ap.error("--out is required")
    if args.why_tau:
        args.out.mkdir(parents=True, exist_ok=True)
        why_tau(args.out, args.why_tau)
        return
    study(args)


def study(args) -> None:
    if args.synthetic:
        synthetic_finsler()
        return
    if args.snake:
        flying_snake(args.snake)
        return
    args.out.mkdir(parents=True, exist_ok=True)
    for tau in [v for v in args.taus.split(",") if v]:
        db = dataset(args.out, f"body_inertia.tau_s={tau}")
        diag = diagnostic(db)
        held_out = float(diag["held-out tau (s)"].iloc[-1])
        res = campaign(db, "momentum", "GMR,GMR+SUDS,GMR+P,GMR+SUDS+P", args)
        # GMR again beside it: the ratio pairs draws of one campaign
        fixed = campaign(db, "momentum-pooled", "GMR,GMR+P", args,
                         "--model-param", f"GMR+P.tau={held_out:.3f}")  # fmt: skip
        fixed["model"] = fixed["model"].replace("GMR+P", "GMR+P (held-out tau)")
        table, ratios = summary(res)
        more, more_ratios = summary(fixed)
        table = pd.concat([table, more[more.learner != "GMR"]])
        table = table.sort_values(["pairs", "learner"], ascending=[False, True])
        ratios = pd.concat([ratios, more_ratios])
        print(f"\n## tau_s = {tau} s\n")
        print("momentum_information:\n" + to_markdown(diag) + "\n")
        print(f"held-out tau given to GMR+P: {held_out:.3f} s\n")
        print(to_markdown(table) + "\n\n" + to_markdown(ratios))
    for ratio in [v for v in args.ratios.split(",") if v]:
        db = dataset(args.out, f"asymmetric_drag.ratio={ratio}")
        table, ratios = summary(campaign(db, "finsler", "phase-only,TLS,TLS+F,GMR,GMR+F", args))
        print(f"\n## ratio = {ratio}\n")
        print(to_markdown(table) + "\n\n" + to_markdown(ratios))


if __name__ == "__main__":
    main()
