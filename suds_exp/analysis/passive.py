"""What the passive shape adds: is r_p informative about the body's motion beyond r_a?

For each frequency, vx is predicted on held-out trials of the same gait from the phase and
the actuated shape's deviations from the mean gait, and again with the passive shape's
deviations added; the ratio of their out-of-sample errors (with a bootstrap interval) says
whether SUDS has anything to use. Shown beside the findings (`suds-exp findings`, the
report, the demo).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from suds_exp.analysis.formatting import interval_column, not_measured
from suds_exp.errors import AnalysisError

#: What `passive_information` means, printed beside it by the demo and the report.
PASSIVE_EXPLANATION = (
    "What the passive shape adds: for each frequency, vx is predicted on held-out trials of "
    "the same gait (fit on one trial, test on another) from the phase and the actuated "
    "shape's deviations from the mean gait (r_a and dr_a/dt, each times a Fourier series "
    "of the phase), and again with the passive shape's deviations (r_p) added. The gain "
    "is the ratio of their RMS errors of vx; at or below 1, r_p carries no information "
    "about the body's motion that r_a lacks (below 1 its extra terms only fit noise), and "
    "then SUDS has nothing to use (F3, F5, F9a need the SUDS learners to beat their plain "
    "twins, F3 by about 2x). On the simulated robot the flippers snap between their stops "
    "at the same phase every cycle, so their state is a function of the phase and r_a and "
    "the gain is not above 1; the paper's robot evidently differs. Run it on your own data "
    "before a long campaign."
)


PASSIVE_COLUMNS = (
    "frequency_hz",
    "n_pairs",
    "rmse_ra",
    "rmse_ra_rp",
    "gain",
    "gain_low",
    "gain_high",
)


def _deviations(phases: list, values: list, order: int) -> list:
    """Each trial's values (n_i, m) minus the condition's mean gait over the phase (a
    Fourier series of order ``order`` fitted on all its trials)."""
    from suds_exp.models import fourier

    b = fourier.basis(np.concatenate(phases), order)
    coef = np.linalg.lstsq(b, np.concatenate(values), rcond=None)[0]
    return [v - fourier.basis(p, order) @ coef for p, v in zip(phases, values, strict=True)]


def _pair_rmse(phase: list, vx: list, x: list, order: int) -> np.ndarray:
    """RMS error of vx (mm/s) for every ordered pair (fit on trial i, test on j != i) of
    a phase-varying linear map on the regressors x[i] (n_i, m): array (n_pairs,)."""
    from suds_exp.models import fourier

    def design(p, xi):
        b = fourier.basis(p, order)
        return np.concatenate([b] + [b * c[:, None] for c in xi.T], axis=1)

    designs = [design(p, xi) for p, xi in zip(phase, x, strict=True)]
    out = []
    for i in range(len(vx)):
        coef = np.linalg.lstsq(designs[i], vx[i], rcond=1e-8)[0]
        for j in range(len(vx)):
            if j != i:
                pred = designs[j] @ coef
                out.append(float(np.sqrt(np.mean((pred - vx[j]) ** 2))))
    return np.array(out)


def passive_information(
    samples: pd.DataFrame,
    n_boot: int = 400,
    seed: int = 0,
    order: int | None = None,
    samples_per_cycle: int = 100,
) -> pd.DataFrame:
    """How much the passive shape r_p tells about vx beyond the phase and r_a, per frequency.

    Parameters
    ----------
    samples : DataFrame
        A preprocessing version's samples (`suds_exp.preprocess.Version.samples`), with
        ``gait``, ``frequency_hz``, ``phase``, ``ra_*``, ``dra_*``, ``rp_*``, ``vx``.
    n_boot : int
        Bootstrap replicates: the ordered trial pairs are resampled with replacement
        within each gait, the medians and their ratio recomputed.
    order : int, optional
        Fourier order in the phase (default the learners' `fourier.PHASE_ORDER`).
    samples_per_cycle : int
        Each trial is decimated to about this many samples per cycle first.

    Returns
    -------
    DataFrame, one row per frequency: ``frequency_hz``, ``n_pairs``, ``rmse_ra`` and
    ``rmse_ra_rp`` (median over pairs of the out-of-sample RMS error of vx, mm/s, from
    phase + r_a deviations and from phase + r_a + r_p deviations), ``gain``
    (rmse_ra / rmse_ra_rp; > 1: r_p adds information, < 1: its terms fit noise) and its
    95 % interval
    ``gain_low``, ``gain_high``.
    """
    from suds_exp.models import fourier

    order = fourier.PHASE_ORDER if order is None else order
    ra = [c for c in samples.columns if c.startswith(("ra_", "dra_"))]
    rp = [c for c in samples.columns if c.startswith("rp_")]
    if not rp:
        raise AnalysisError("passive_information: the samples have no passive shape (rp_*)")
    rows = []
    for freq, at_f in samples.groupby("frequency_hz", sort=True):
        errors = []
        for _, cond in at_f.groupby("gait", sort=True):
            trials = []
            for _, tr in cond.groupby("trial_id", sort=True):
                per_cycle = len(tr) / max(tr["cycle"].nunique(), 1)
                step = max(1, int(round(per_cycle / samples_per_cycle)))
                trials.append(tr.iloc[::step])
            if len(trials) < 2:
                continue
            phase = [np.mod(t["phase"].to_numpy(float), 2 * np.pi) for t in trials]
            d_ra = _deviations(phase, [t[ra].to_numpy(float) for t in trials], order)
            d_rp = _deviations(phase, [t[rp].to_numpy(float) for t in trials], order)
            vx = [t["vx"].to_numpy(float) for t in trials]
            both = [np.c_[a, b] for a, b in zip(d_ra, d_rp, strict=True)]
            errors.append(
                np.c_[_pair_rmse(phase, vx, d_ra, order), _pair_rmse(phase, vx, both, order)]
            )
        if not errors:
            continue
        med = np.median(np.vstack(errors), axis=0)
        rng = np.random.default_rng(np.random.SeedSequence([seed, int(round(freq * 1e6))]))
        gains = []
        for _ in range(n_boot):
            draw = np.vstack([e[rng.integers(0, len(e), len(e))] for e in errors])
            m = np.median(draw, axis=0)
            gains.append(m[0] / m[1])
        low, high = np.percentile(gains, [2.5, 97.5]) if gains else (np.nan, np.nan)
        rows.append(
            {
                "frequency_hz": float(freq),
                "n_pairs": int(sum(len(e) for e in errors)),
                "rmse_ra": float(med[0]),
                "rmse_ra_rp": float(med[1]),
                "gain": float(med[0] / med[1]),
                "gain_low": float(low),
                "gain_high": float(high),
            }
        )
    return pd.DataFrame(rows)


def campaign_passive_information(store, campaign: str, **kwargs) -> pd.DataFrame:
    """`passive_information` of the samples of the version campaign ``campaign`` used."""
    from suds_exp.errors import SudsError
    from suds_exp.preprocess import get_version

    try:
        row = store.query_df("SELECT prep_version FROM campaigns WHERE name = ?", [campaign])
        samples = get_version(store, row["prep_version"].iloc[0]).samples() if len(row) else None
    except SudsError:
        samples = None
    if samples is None or samples.empty:
        # results without stored samples (imported, synthetic): nothing to measure
        return not_measured(PASSIVE_COLUMNS, "the campaign's samples are not stored")
    if not any(c.startswith("rp_") for c in samples):
        return not_measured(PASSIVE_COLUMNS, "the samples have no passive shape (rp_*)")
    table = passive_information(samples, **kwargs)
    if table.empty:
        return not_measured(
            PASSIVE_COLUMNS,
            f"no condition has two trials at one frequency in the {len(samples):,} stored "
            "samples (a pair fits on one trial and tests on another)",
        )
    return table


def passive_reason(table: pd.DataFrame) -> str:
    """Why an empty passive-information table (`campaign_passive_information`) is empty."""
    return table.attrs.get("reason", "no pair of trials to measure it on")


def passive_display(table: pd.DataFrame) -> pd.DataFrame:
    """The passive-information table as shown: frequency, the two errors, gain [interval]."""
    return pd.DataFrame(
        {
            "frequency (Hz)": table["frequency_hz"].map(lambda f: f"{f:.3g}"),
            "RMSE vx, phase + r_a (mm/s)": table["rmse_ra"].map(lambda v: f"{v:.2f}"),
            "+ r_p (mm/s)": table["rmse_ra_rp"].map(lambda v: f"{v:.2f}"),
            "gain [95% interval]": interval_column(table, "gain"),
        }
    )
