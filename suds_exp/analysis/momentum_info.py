"""What the velocity history adds: the out-of-sample error of GMR with a momentum state
(`GMR+P`) against GMR's, on the user's own samples, before a campaign.

A lag of the body velocity shows, and can be told from a different quasi-static map,
only across speeds: at one gait frequency a lagged periodic velocity is just another
periodic velocity. So the diagnostic holds each gait frequency out in turn, fits GMR and
GMR+P on the trials at the other frequencies (up to `cycles` cycles of each, from its
second cycle, past the start from rest; a few trials per frequency, decimated as a
campaign decimates) and tests both on the trials at the held-out frequency. The ratio of
the median errors (GMR+P / GMR, RMSE of vx) has a bootstrap interval over the held-out
trials; "helps" when the whole interval lies below 1.

Two kinds of time constant are reported. ``tau_vx_s``, ``tau_vy_s``, ``tau_wz_s``: GMR+P's
own estimates, one per component, fitted on all frequencies together (in-sample). A
component whose lagged part is small against the map's misfit leaves that fit nearly
flat in its time constant (vx of the simulated swimmer: 0.2-0.5 s within 12 % of the
best), so these can be far off. ``tau_s``: the one time constant of the body that best
predicts each held-out speed (GMR+P with that lag on every component, refitted per held-
out frequency; the error summed over vx, vy, wz, each relative to GMR's): the value to
give `GMR+P` (``tau``) in a campaign, whose training sets hold one condition each.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from suds_exp.analysis.formatting import interval_column, not_measured

#: Columns of the momentum-information table, one row per held-out frequency, then "all".
MOMENTUM_COLUMNS = (
    "held_out_hz",
    "n_trials",
    "rmse_gmr",
    "rmse_gmr_p",
    "ratio",
    "ratio_low",
    "ratio_high",
    "verdict",
    "tau_vx_s",
    "tau_vy_s",
    "tau_wz_s",
    "tau_s",
)
#: Body velocity components the held-out time constant weighs
COMPONENTS = ("vx", "vy", "wz")
#: Shared time constants (s) the held-out profile starts from (0 = GMR); a bounded
#: search then refines between the neighbours of the best
TAU_GRID = (0.0, 0.04, 0.08, 0.16, 0.32, 0.64, 1.28)
#: What `momentum_information` means, printed beside it.
MOMENTUM_EXPLANATION = (
    "What the velocity history adds: each gait frequency held out in turn, GMR and GMR+P "
    "(GMR with a learned momentum state) fitted on the others and tested on it; ratio = "
    "median RMSE of vx of GMR+P / GMR with a 95% bootstrap interval over held-out trials; "
    "'helps' when the interval lies below 1. tau vx, vy, wz: GMR+P's own time constants (s) "
    "fitted on all frequencies; held-out tau: the one time constant (s) that best predicts "
    "each held-out speed, the value to give GMR+P (tau) in a campaign."
)


def _windows(
    samples: pd.DataFrame, cycles: int, samples_per_cycle: int, max_trials: int
) -> pd.DataFrame:
    """Up to ``cycles`` cycles of each trial, from its second cycle on, every k-th sample
    so that a cycle keeps about ``samples_per_cycle``; the first ``max_trials`` trials of
    each frequency (column ``_f``)."""
    trials = samples.drop_duplicates("trial_id").sort_values("trial_id")
    chosen = trials.groupby("_f").head(max_trials)["trial_id"]
    samples = samples[samples["trial_id"].isin(chosen)]
    first = samples.groupby("trial_id")["cycle"].transform("min")
    keep = (samples["cycle"] >= first + 1) & (samples["cycle"] < first + 1 + cycles)
    samples = samples[keep]
    per_cycle = samples.groupby("trial_id")["cycle"].transform("size") / cycles
    step = np.maximum(1, np.round(per_cycle / samples_per_cycle)).astype(int)
    position = samples.groupby("trial_id").cumcount()
    return samples[(position % step) == 0]


def _trial_rmse(pred: pd.DataFrame, test: pd.DataFrame) -> np.ndarray:
    err = (pred["vx"].to_numpy() - test["vx"].to_numpy()) ** 2
    return np.sqrt(pd.Series(err, index=test.index).groupby(test["trial_id"]).mean()).to_numpy()


def momentum_information(
    samples: pd.DataFrame,
    frequencies: pd.Series,
    cycles: int = 4,
    n_boot: int = 400,
    seed: int = 0,
    samples_per_cycle: int = 50,
    max_trials: int = 6,
) -> pd.DataFrame:
    """The momentum-information table (`MOMENTUM_COLUMNS`) of a samples frame.

    ``frequencies``: each trial's gait frequency in Hz, indexed by trial_id. Empty when
    the samples hold fewer than two frequencies (nothing to hold out across speeds).
    ``cycles`` cycles of at most ``max_trials`` trials per frequency are used, decimated
    to about ``samples_per_cycle`` samples a cycle (as a campaign decimates), so the cost
    stays that of a few small fits whatever the recording's size. Errors in mm/s, time
    constants in s.
    """
    from suds_exp.models import make_model

    freq = samples["trial_id"].map(frequencies).round(6)
    levels = sorted(freq.dropna().unique())
    if len(levels) < 2:
        return pd.DataFrame(columns=MOMENTUM_COLUMNS)
    data = _windows(samples.assign(_f=freq.to_numpy()), cycles, samples_per_cycle, max_trials)
    rng = np.random.default_rng(seed)
    rows, all_gmr, all_p = [], [], []
    for f in levels:
        train, test = data[data["_f"] != f], data[data["_f"] == f]
        if train.empty or test.empty:
            continue
        gmr = _trial_rmse(make_model("GMR").fit(train).predict(test), test)
        p = _trial_rmse(make_model("GMR+P").fit(train).predict(test), test)
        all_gmr.append(gmr)
        all_p.append(p)
        rows.append(_row(f, gmr, p, rng, n_boot))
    if not rows:
        return pd.DataFrame(columns=MOMENTUM_COLUMNS)
    rows.append(_row("all", np.concatenate(all_gmr), np.concatenate(all_p), rng, n_boot))
    tau = make_model("GMR+P").fit(data).tau_
    table = pd.DataFrame(rows)
    table["tau_vx_s"], table["tau_vy_s"], table["tau_wz_s"] = tau
    table["tau_s"] = heldout_tau(data, levels)
    return table[list(MOMENTUM_COLUMNS)]


def heldout_errors(data: pd.DataFrame, levels, tau: float) -> np.ndarray:
    """Median over ``levels`` of GMR+P's RMSE on each held-out frequency, (3,) for vx, vy
    (mm/s) and wz (rad/s): GMR+P with time constant ``tau`` (s) on every component,
    fitted on the other frequencies of ``data`` (frequency in column ``_f``)."""
    from suds_exp.models import make_model

    per_fold = []
    for f in levels:
        train, test = data[data["_f"] != f], data[data["_f"] == f]
        if train.empty or test.empty:
            continue
        pred = make_model("GMR+P", tau=float(tau)).fit(train).predict(test)
        per_fold.append(
            [np.sqrt(np.mean((pred[c].to_numpy() - test[c].to_numpy()) ** 2)) for c in COMPONENTS]
        )
    return np.median(per_fold, axis=0)


def heldout_tau(data: pd.DataFrame, levels) -> float:
    """The one time constant (s) with which GMR+P best predicts each held-out frequency.

    ``data``: samples with their frequency in column ``_f``; ``levels``: the frequencies.
    The score of a candidate tau is the sum over vx, vy and wz of `heldout_errors`, each
    relative to GMR's (tau = 0). The best of `TAU_GRID` is refined by a bounded search
    between its neighbours. 0 when no lag predicts better than GMR.
    """
    from scipy.optimize import minimize_scalar

    base = heldout_errors(data, levels, 0.0)
    base[base <= 0] = 1.0

    def score(tau: float) -> float:
        return float(np.sum(heldout_errors(data, levels, tau) / base))

    scores = [len(COMPONENTS)] + [score(t) for t in TAU_GRID[1:]]
    i = int(np.argmin(scores))
    if i == 0:
        return 0.0
    lo, hi = TAU_GRID[i - 1], TAU_GRID[min(i + 1, len(TAU_GRID) - 1)]
    best = minimize_scalar(score, bounds=(lo, hi), method="bounded", options={"xatol": 0.01})
    return float(best.x) if best.fun < scores[i] else float(TAU_GRID[i])


def _row(held_out, gmr: np.ndarray, p: np.ndarray, rng, n_boot: int) -> dict:
    ratio = float(np.median(p) / np.median(gmr))
    idx = rng.integers(0, len(gmr), size=(n_boot, len(gmr)))
    boot = np.median(p[idx], axis=1) / np.median(gmr[idx], axis=1)
    low, high = (float(v) for v in np.percentile(boot, [2.5, 97.5]))
    return {
        "held_out_hz": held_out if held_out == "all" else f"{held_out:.3g}",
        "n_trials": len(gmr),
        "rmse_gmr": float(np.median(gmr)),
        "rmse_gmr_p": float(np.median(p)),
        "ratio": ratio,
        "ratio_low": low,
        "ratio_high": high,
        "verdict": "helps" if high < 1 else "does not help",
    }


def campaign_momentum_information(store, campaign: str, **kwargs) -> pd.DataFrame:
    """`momentum_information` of the samples of the version campaign ``campaign`` used;
    empty, with its reason in ``attrs["reason"]``, when it cannot be measured."""
    from suds_exp.errors import SudsError
    from suds_exp.preprocess import get_version

    try:
        row = store.query_df("SELECT prep_version FROM campaigns WHERE name = ?", [campaign])
        samples = get_version(store, row["prep_version"].iloc[0]).samples() if len(row) else None
        trials = store.query_df("SELECT id AS trial_id, frequency_hz FROM trials")
    except SudsError:
        samples = None
    if samples is None or samples.empty:
        return not_measured(MOMENTUM_COLUMNS, "the campaign's samples are not stored")
    table = momentum_information(samples, trials.set_index("trial_id")["frequency_hz"], **kwargs)
    if table.empty:
        return not_measured(
            MOMENTUM_COLUMNS, "the samples hold one gait frequency; a lag shows only across speeds"
        )
    return table


def momentum_reason(table: pd.DataFrame) -> str:
    """Why an empty momentum-information table is empty."""
    return table.attrs.get("reason", "no two gait frequencies to measure it on")


def momentum_display(table: pd.DataFrame) -> pd.DataFrame:
    """The momentum-information table as shown."""
    return pd.DataFrame(
        {
            "held out (Hz)": table["held_out_hz"],
            "trials": table["n_trials"],
            "RMSE vx GMR (mm/s)": table["rmse_gmr"].map(lambda v: f"{v:.2f}"),
            "GMR+P (mm/s)": table["rmse_gmr_p"].map(lambda v: f"{v:.2f}"),
            "ratio [95% interval]": interval_column(table, "ratio"),
            "verdict": table["verdict"],
            "tau vx, vy, wz (s)": [
                f"{a:.3f}, {b:.3f}, {c:.3f}"
                for a, b, c in zip(
                    table["tau_vx_s"], table["tau_vy_s"], table["tau_wz_s"], strict=True
                )
            ],
            "held-out tau (s)": table["tau_s"].map(lambda v: f"{v:.3f}"),
        }
    )


def momentum_section(store, campaign: str, out_dir) -> str:
    """The report's momentum-information section as HTML; writes
    ``momentum_information.csv`` and ``.md`` into ``out_dir`` when it is measurable."""
    import html

    from suds_exp.analysis.formatting import to_html, to_markdown, write_table

    table = campaign_momentum_information(store, campaign)
    head = '<h3 id="momentum-information">What the velocity history adds</h3>'
    if table.empty:
        return f"\n{head}\n<p>Not measurable: {html.escape(momentum_reason(table))}.</p>"
    shown = momentum_display(table)
    files = write_table(table, out_dir, "momentum_information", 3, to_markdown(shown))
    links = " ".join(
        f'<a href="{html.escape(p.name)}">{html.escape(p.name)}</a>' for p in files.values()
    )
    return "\n".join(
        [
            "",
            head,
            f'<p class="note">{html.escape(MOMENTUM_EXPLANATION)}</p>',
            to_html(shown),
            f"<p>Files: {links}</p>",
        ]
    )
