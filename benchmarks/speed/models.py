"""Learner benchmark: fit/predict times, our GMR against the `gmr` package, A-GBR ablation.

Usage (from the repository root)::

    OMP_NUM_THREADS=1 .venv/bin/python -m benchmarks.speed.models [--repeats 7] [--boots 3]
        [--data sim|synthetic] [--quick]

Data: by default the physics simulator (`suds_exp.sim`, nominal configuration), with
r_a = (phi1, phi2), r_p = the four flipper angles (k = 4), rates by central differences,
phase = commanded phase, every condition decimated to 100 samples per cycle as the
campaign does, and Gaussian noise of 1 mm/s on vx, vy and 0.01 rad/s on wz (the
simulator's velocities are exact). `--data synthetic` uses the closed-form
rate-independent swimmer of `suds_exp.testing.synthetic_swimmer` (passive="travel",
velocity="finsler") instead.

Sections:
1. fit and predict seconds of every learner (the survey's baselines too) at 30 and 48
   training cycles (~3000 and ~4800 samples), predicting one 20-cycle test trial (2000
   samples); medians over `--repeats` runs, single-threaded BLAS recommended (the
   campaign runs one job a core). Wall-clock and CPU seconds of this process: on a
   shared machine the CPU seconds (single-threaded) do not depend on the others' load.
   Then each learner's fit+predict CPU seconds against the paper's five together.
2. Our EM + conditional mean against `gmr.GMM.from_samples` + `GMM.predict` at equal K
   on the same standardised data (GMR without augmentation or branching), with held-out
   RMSE of vx so the speed is compared at comparable accuracy.
3. Ablation of augmentation x branching for GMR and GMR+SUDS: mean held-out RMSE of vx
   (mm/s) over `--boots` random 30-cycle training windows of O at 1/2 Hz, tested on a
   different trial of O at 1/2 Hz (same), O at 1 Hz and O at 1/3 Hz (other speed), and
   D+ at 1/2 Hz (other gait).
4. Solver of the MLP baselines (why it is L-BFGS): for the MLP and MLP+SUDS networks of
   `baselines.BASELINES` on 30 training cycles, seeds 0 and 1, the held-out RMSE
   of vx (a different 20-cycle trial of O at 1/2 Hz) and the R^2 on a 10 % validation
   split after 5 ... 200 epochs of Adam (lr 1e-3, the former default), then the same
   held-out RMSE and the fit CPU seconds of the default, L-BFGS with at most 100 and
   200 iterations; then the former default (Adam with early stopping) against L-BFGS on
   four test trials (O at 1/2, 1 and 1/3 Hz, D+ at 1/2 Hz).

``--quick``: section 1 alone, phase-only and TLS once, on the synthetic swimmer (a smoke
run, no figure).
"""

from __future__ import annotations

import time
from statistics import median

import numpy as np
import pandas as pd

from benchmarks._data import PAPER, SURVEY, swimmer_samples
from benchmarks._harness import script_parser
from suds_exp.models import make_model
from suds_exp.models.mixture import conditional_mean, fit_mixture
from suds_exp.models.registry import LEARNERS, SURVEY_LEARNERS

SAMPLES_PER_CYCLE = 100
#: The learners `--models survey` adds to the paper's five.
SURVEY_EXTRA = tuple(n for n in SURVEY_LEARNERS if n not in LEARNERS)


def _sim_trials(conditions, n_cycles, repeats, seed):
    """{(gait, f): [samples frame per repeat]} from the physics simulator."""
    from suds_exp.sim.config import SimConfig
    from suds_exp.sim.dataset import plan_trials, simulate_trials

    cfg = SimConfig()
    rate = cfg.measurement.sample_rate_hz
    rng = np.random.default_rng(seed)
    out = {}
    tid = 1
    specs = []
    for gait, f in conditions:
        specs += plan_trials([gait], [f], repeats, (n_cycles, n_cycles), seed)
    truths = simulate_trials(specs, cfg)
    for spec, tr in zip(specs, truths, strict=True):
        step = max(1, int(round(rate / (SAMPLES_PER_CYCLE * spec.frequency_hz))))
        t = tr["t"]
        ra = np.column_stack([tr["phi1"], tr["phi2"]])
        rp = np.column_stack([tr[f"flipper_{i}"] for i in range(1, 5)])
        dra = np.gradient(ra, t, axis=0)
        drp = np.gradient(rp, t, axis=0)
        sl = slice(None, None, step)
        n = len(t[sl])
        d = {
            "trial_id": tid,
            "frame": np.arange(len(t))[sl],
            "t": t[sl],
            "phase": tr["phase_cmd"][sl],
            "ra_1": ra[sl, 0],
            "ra_2": ra[sl, 1],
            "dra_1": dra[sl, 0],
            "dra_2": dra[sl, 1],
        }
        for i in range(4):
            d[f"rp_{i + 1}"] = rp[sl, i]
        for i in range(4):
            d[f"drp_{i + 1}"] = drp[sl, i]
        noise = rng.standard_normal((n, 3)) * [1.0, 1.0, 0.01]
        for j, c in enumerate(("vx", "vy", "wz")):
            d[c] = tr[c][sl] + noise[:, j]
        frame = pd.DataFrame(d)
        frame["cycle"] = np.floor((frame["phase"] - frame["phase"].iloc[0]) / (2 * np.pi))
        out.setdefault((spec.gait, spec.frequency_hz), []).append(frame)
        tid += 1
    return out


def _synthetic_trials(conditions, n_cycles, repeats, seed):
    out = {}
    tid = 1
    for gait, f in conditions:
        for _ in range(repeats):
            out.setdefault((gait, f), []).append(
                swimmer_samples(n_cycles, gait, f, seed * 1000 + tid, tid)
            )
            tid += 1
    return out


def _window(frame, first_cycle, n_cycles):
    c = np.floor((frame["phase"] - frame["phase"].iloc[0]) / (2 * np.pi))
    return frame[(c >= first_cycle) & (c < first_cycle + n_cycles)]


def _rmse(pred, test):
    return float(np.sqrt(((pred["vx"] - test["vx"]) ** 2).mean()))


def timings(trials, repeats, learners=None):
    """Section 1 for ``learners`` ((name, parameters) pairs; default: the paper's and the
    survey's)."""
    base = trials[("O", 0.5)]
    train = {30: _window(base[0], 0, 30), 48: pd.concat([base[0], _window(base[1], 0, 18)])}
    test = _window(base[2], 0, 20)
    learners = learners or [*PAPER, *SURVEY]
    print("\n## 1. Fit and predict time (s), medians of", repeats, "runs; test trial", len(test))
    print(
        "| learner | train samples | fit s | predict s | fit+predict s | fit+predict CPU s "
        "| RMSE vx mm/s |"
    )
    print("|---|---|---|---|---|---|---|")
    cpu = {}
    for n_cycles, tr in train.items():
        for name, params in learners:
            fits, preds, cpus = [], [], []
            for _ in range(repeats):
                m = make_model(name, **params)
                c0, t0 = time.process_time(), time.perf_counter()
                m.fit(tr)
                t1 = time.perf_counter()
                p = m.predict(test)
                t2, c2 = time.perf_counter(), time.process_time()
                fits.append(t1 - t0)
                preds.append(t2 - t1)
                cpus.append(c2 - c0)
            label = name + (" (rollout)" if params.get("mode") == "rollout" else "")
            cpu[(label, n_cycles)] = median(cpus)
            print(
                f"| {label} | {len(tr)} ({n_cycles} cycles) | {median(fits):.4f} | "
                f"{median(preds):.4f} | {median(fits) + median(preds):.4f} | "
                f"{median(cpus):.4f} | {_rmse(p, test):.2f} |"
            )
    five = LEARNERS
    if any((n, c) not in cpu for n in five for c in train):
        return
    print("\nfit+predict CPU seconds against the paper's five together (measured mode):")
    for n_cycles in train:
        base = sum(cpu[(n, n_cycles)] for n in five)
        extra = {lab: v for (lab, n), v in cpu.items() if n == n_cycles and lab in SURVEY_EXTRA}
        parts = ", ".join(f"{lab} {v / base:.2f}" for lab, v in extra.items())
        total = (base + sum(extra.values())) / base
        print(
            f"{n_cycles} cycles: five {base:.3f} s; {parts}; "
            f"five + survey learners = {total:.2f}x the five (target <= 3x)"
        )


def versus_gmr(trials, repeats, K=12):
    import gmr

    base = trials[("O", 0.5)]
    tr, te = _window(base[0], 0, 30), _window(base[2], 0, 20)
    cin, cout = ["ra_1", "ra_2", "dra_1", "dra_2"], ["vx", "vy", "wz"]
    Z = tr[cin + cout].to_numpy()
    mu, sd = Z.mean(0), Z.std(0)
    Zs = (Z - mu) / sd
    Xte = (te[cin].to_numpy() - mu[:4]) / sd[:4]
    d = len(cin)

    def ours(max_iter, tol):
        mix = fit_mixture(Zs, K, None, max_iter, tol, 1e-3, np.random.default_rng(0))
        y = conditional_mean(mix.priors, mix.means, mix.covariances, np.arange(d), Xte)
        return y, mix.n_iter

    def theirs():
        g = gmr.GMM(n_components=K, random_state=0)
        g.from_samples(Zs, n_iter=100, init_params="kmeans++")
        return g.predict(np.arange(d), Xte), None

    rows = [
        ("ours, defaults (max_iter=60, tol=1e-3)", lambda: ours(60, 1e-3)),
        ("ours, tight (max_iter=100, tol=1e-5)", lambda: ours(100, 1e-5)),
        ("gmr 2.0.3 from_samples(kmeans++, n_iter=100) + predict", theirs),
    ]
    print(f"\n## 2. Our EM + GMR vs the gmr package, K={K}, {len(tr)} train / {len(te)} test")
    print("| implementation | fit+predict s (median) | EM iterations | RMSE vx mm/s |")
    print("|---|---|---|---|")
    res = {}
    for label, fn in rows:
        ts = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            y, it = fn()
            ts.append(time.perf_counter() - t0)
        err = float(np.sqrt((((y[:, 0] * sd[d]) + mu[d] - te["vx"].to_numpy()) ** 2).mean()))
        res[label] = median(ts)
        print(f"| {label} | {median(ts):.4f} | {it if it else '-'} | {err:.2f} |")
    g = res[rows[2][0]]
    print(f"speed-up vs gmr: defaults x{g / res[rows[0][0]]:.1f}, tight x{g / res[rows[1][0]]:.1f}")


def ablation(trials, boots, seed):
    rng = np.random.default_rng(seed)
    base = trials[("O", 0.5)]
    tests = {
        "same (O 1/2 Hz)": None,
        "O 1 Hz": _window(trials[("O", 1.0)][0], 0, 20),
        "O 1/3 Hz": _window(trials[("O", 1 / 3)][0], 0, 20),
        "D+ 1/2 Hz": _window(trials[("D+", 0.5)][0], 0, 20),
    }
    combos = [
        (aug, br)
        for aug in ("homogeneous", "dilation", "none")
        for br in ("none", "filter", "history")
    ]
    print(f"\n## 3. Ablation: mean RMSE vx (mm/s) over {boots} training draws of 30 cycles")
    print("| learner | augment | branching | " + " | ".join(tests) + " |")
    print("|---|---|---|" + "---|" * len(tests))
    draws = []
    for _ in range(boots):
        i, j = rng.choice(len(base), size=2, replace=False)
        n_c = int(np.floor((base[i]["phase"].iloc[-1] - base[i]["phase"].iloc[0]) / (2 * np.pi)))
        start = int(rng.integers(0, max(1, n_c - 30 + 1)))
        draws.append((_window(base[i], start, 30), _window(base[j], 0, 20)))
    for name in ("GMR", "GMR+SUDS"):
        for aug, br in combos:
            errs = {k: [] for k in tests}
            for tr, same in draws:
                m = make_model(name, augment=aug, branching=br).fit(tr)
                for k, te in tests.items():
                    te = same if te is None else te
                    errs[k].append(_rmse(m.predict(te), te))
            cells = " | ".join(f"{np.mean(v):.2f}" for v in errs.values())
            print(f"| {name} | {aug} | {br} | {cells} |")


def mlp_curve(trials, epochs=(5, 10, 20, 30, 40, 60, 80, 100, 150, 200)):
    from sklearn.base import clone
    from sklearn.model_selection import train_test_split

    base = trials[("O", 0.5)]
    tr, te = _window(base[0], 0, 30), _window(base[2], 0, 20)
    print("\n## 4. MLP solver: Adam's held-out RMSE vx mm/s / validation R^2, by epoch")
    print("| learner | seed | ms/epoch | " + " | ".join(str(e) for e in epochs) + " |")
    print("|---|---|---|" + "---|" * len(epochs))
    for name in ("MLP", "MLP+SUDS"):
        for seed in (0, 1):
            m = make_model(name, random_state=seed).fit(tr)  # for its scalers and columns
            X = m.x_scaler_.transform(tr[m.columns_in_].to_numpy()).astype(m.dtype)
            Y = m.y_scaler_.transform(tr[m.columns_out_].to_numpy()).astype(m.dtype)
            Xt = m.x_scaler_.transform(te[m.columns_in_].to_numpy()).astype(m.dtype)
            Xa, Xv, Ya, Yv = train_test_split(X, Y, test_size=0.1, random_state=seed)
            net = clone(m.estimator).set_params(
                random_state=seed, solver="adam", learning_rate_init=1e-3, early_stopping=False
            )
            cells, t0 = [], time.process_time()
            for epoch in range(1, max(epochs) + 1):
                net.partial_fit(Xa, Ya)
                if epoch in epochs:
                    vx = m.y_scaler_.inverse_transform(net.predict(Xt).astype(float))[:, 0]
                    rmse = float(np.sqrt(np.mean((vx - te["vx"].to_numpy()) ** 2)))
                    cells.append(f"{rmse:.2f} / {net.score(Xv, Yv):.4f}")
            ms = 1000 * (time.process_time() - t0) / max(epochs)
            print(f"| {name} | {seed} | {ms:.0f} | " + " | ".join(cells) + " |")
    print("\nThe default, L-BFGS, on the same draws: held-out RMSE vx mm/s / fit CPU s")
    print("| learner | seed | max_iter 100 | max_iter 200 |")
    print("|---|---|---|---|")
    for name in ("MLP", "MLP+SUDS"):
        for seed in (0, 1):
            cells = []
            for max_iter in (100, 200):
                c0 = time.process_time()
                m = make_model(name, random_state=seed, max_iter=max_iter).fit(tr)
                cells.append(f"{_rmse(m.predict(te), te):.2f} / {time.process_time() - c0:.2f}")
            print(f"| {name} | {seed} | " + " | ".join(cells) + " |")
    tests = {
        "O 1/2 Hz": te,
        "O 1 Hz": _window(trials[("O", 1.0)][0], 0, 20),
        "O 1/3 Hz": _window(trials[("O", 1 / 3)][0], 0, 20),
        "D+ 1/2 Hz": _window(trials[("D+", 0.5)][0], 0, 20),
    }
    former = {
        "solver": "adam",
        "learning_rate_init": 1e-3,
        "max_iter": 300,
        "early_stopping": True,
        "validation_fraction": 0.1,
        "n_iter_no_change": 10,
        "tol": 1e-4,
    }
    print("\nFormer default (Adam, early stopping) against L-BFGS, trained on O at 1/2 Hz:")
    print("fit+predict CPU s and held-out RMSE vx mm/s, means over seeds 0 and 1")
    print("| learner | solver | CPU s | " + " | ".join(tests) + " |")
    print("|---|---|---|" + "---|" * len(tests))
    for name in ("MLP", "MLP+SUDS"):
        for label, params in (("Adam + early stopping", former), ("L-BFGS 200", {})):
            cpu, errs = [], {k: [] for k in tests}
            for seed in (0, 1):
                c0 = time.process_time()
                m = make_model(name, random_state=seed, **params).fit(tr)
                m.predict(te)
                cpu.append(time.process_time() - c0)
                for k, t in tests.items():
                    errs[k].append(_rmse(m.predict(t), t))
            cells = " | ".join(f"{np.mean(v):.2f}" for v in errs.values())
            print(f"| {name} | {label} | {np.mean(cpu):.2f} | {cells} |")


def main(argv=None):
    ap = script_parser(__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--boots", type=int, default=3)
    ap.add_argument("--data", choices=("sim", "synthetic"), default="sim")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--skip", nargs="*", default=[], choices=("timing", "gmr", "ablation", "curve"))
    args = ap.parse_args(argv)
    learners = None
    if args.quick:
        args.data, args.repeats, args.skip = "synthetic", 1, ["gmr", "ablation", "curve"]
        learners = PAPER[:2]
    conditions = [("O", 0.5), ("O", 1.0), ("O", 1 / 3), ("D+", 0.5)]
    t0 = time.perf_counter()
    make = _sim_trials if args.data == "sim" else _synthetic_trials
    trials = make(conditions, 30, 3, args.seed)
    print(f"# Learner benchmark ({args.data} data, built in {time.perf_counter() - t0:.1f} s)")
    if "timing" not in args.skip:
        timings(trials, args.repeats, learners)
    if "gmr" not in args.skip:
        versus_gmr(trials, args.repeats)
    if "ablation" not in args.skip:
        ablation(trials, args.boots, args.seed)
    if "curve" not in args.skip:
        mlp_curve(trials)


if __name__ == "__main__":
    main()
