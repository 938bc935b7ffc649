"""Localise the gap: where do replay and measurement disagree?

Four views of the residual (simulated minus measured body velocity), each a long table
with one row per (view, bin, channel): RMS by condition (gait x frequency), by phase
(with a band: the 2.5-97.5% range of the RMS over trial bootstrap replicates), by region
of shape space (a grid over r_a = (phi1, phi2)) and over the trial's time (window
position in the trial, 0 = start, 1 = end). Plus, for the gap no candidate explains, the
correlation of the residual with measured signals.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from suds_exp.discrepancy.replay import CHANNELS

N_PHASE_BINS = 12
N_SHAPE_BINS = 5
N_TIME_BINS = 5


def _phase_bins(phase: np.ndarray) -> np.ndarray:
    """Bin index 0..N_PHASE_BINS-1 of each phase (rad); -1 where it is not finite."""
    ph = np.where(np.isfinite(phase), np.mod(phase, 2 * np.pi), 0.0)
    b = np.minimum((ph / (2 * np.pi) * N_PHASE_BINS).astype(int), N_PHASE_BINS - 1)
    return np.where(np.isfinite(phase), b, -1)


def _rms_table(res: np.ndarray, key: np.ndarray, trial: np.ndarray, rng, n_boot: int) -> list:
    """RMS per key and channel with a trial-bootstrap band.

    res (n, 3) residual samples; key (n,) bin labels; trial (n,) trial of each sample.
    """
    rows = []
    trials, t_inv = np.unique(trial, return_inverse=True)
    keys, k_inv = np.unique(key, return_inverse=True)
    # sums of squares and counts per (trial, key): the bootstrap resamples trials
    ss = np.zeros((len(trials), len(keys), 3))
    nn = np.zeros((len(trials), len(keys)))
    ok = np.all(np.isfinite(res), axis=1)
    np.add.at(ss, (t_inv[ok], k_inv[ok]), res[ok] ** 2)
    np.add.at(nn, (t_inv[ok], k_inv[ok]), 1)
    w = rng.multinomial(len(trials), np.full(len(trials), 1 / len(trials)), size=n_boot)
    with np.errstate(invalid="ignore", divide="ignore"):
        rms = np.sqrt(ss.sum(0) / nn.sum(0)[:, None])
        boot = np.sqrt(np.einsum("bt,tkc->bkc", w, ss) / (w @ nn)[:, :, None])
    with warnings.catch_warnings():
        # a bin no replicate reaches has no band: NaN is the honest answer
        warnings.simplefilter("ignore", RuntimeWarning)
        lo = np.nanquantile(boot, 0.025, axis=0)
        hi = np.nanquantile(boot, 0.975, axis=0)
    for j, k in enumerate(keys):
        for c, ch in enumerate(CHANNELS):
            rows.append((k, ch, rms[j, c], lo[j, c], hi[j, c], int(nn[:, j].sum())))
    return rows


def localise(
    info: pd.DataFrame,
    residual: np.ndarray,
    phase: np.ndarray,
    ra: np.ndarray,
    rng: np.random.Generator,
    n_boot: int = 200,
) -> pd.DataFrame:
    """The four views of the residual as one long table.

    Parameters
    ----------
    info : DataFrame, one row per window (trial_id, gait, frequency_hz, t_rel)
    residual : array of shape (n_windows, n_samples, 3)
        Simulated minus measured vx, vy (mm/s), wz (rad/s); NaN padded.
    phase : array of shape (n_windows, n_samples), rad
    ra : array of shape (n_windows, n_samples, 2), rad

    Returns
    -------
    DataFrame with columns view ('condition' | 'phase' | 'shape' | 'time'), gait,
    frequency_hz, bin (int), x, y (bin centres: phase rad, phi1/phi2 rad, t_rel), channel,
    rms, band_lo, band_hi, n.
    """
    n_win, n_s = residual.shape[:2]
    res = residual.reshape(-1, 3)
    trial = np.repeat(info["trial_id"].to_numpy(), n_s)
    out = []
    cond = [f"{g}|{f:.6f}" for g, f in zip(info["gait"], info["frequency_hz"], strict=True)]
    for k, ch, rms, lo, hi, n in _rms_table(res, np.repeat(cond, n_s), trial, rng, n_boot):
        g, f = k.split("|")
        out.append(("condition", g, float(f), 0, np.nan, np.nan, ch, rms, lo, hi, n))
    pbin = _phase_bins(phase.reshape(-1))
    for k, ch, rms, lo, hi, n in _rms_table(res, pbin, trial, rng, n_boot):
        if k >= 0:
            x = (k + 0.5) * 2 * np.pi / N_PHASE_BINS
            out.append(("phase", None, np.nan, int(k), x, np.nan, ch, rms, lo, hi, n))
    r = ra.reshape(-1, 2)
    finite = np.all(np.isfinite(r), axis=1)
    edges = [np.quantile(r[finite, i], np.linspace(0, 1, N_SHAPE_BINS + 1)) for i in (0, 1)]
    ix = np.clip(np.searchsorted(edges[0], r[:, 0], side="right") - 1, 0, N_SHAPE_BINS - 1)
    iy = np.clip(np.searchsorted(edges[1], r[:, 1], side="right") - 1, 0, N_SHAPE_BINS - 1)
    sbin = np.where(finite, ix * N_SHAPE_BINS + iy, -1)
    for k, ch, rms, lo, hi, n in _rms_table(res, sbin, trial, rng, n_boot):
        if k >= 0:
            i, j = divmod(int(k), N_SHAPE_BINS)
            x = 0.5 * (edges[0][i] + edges[0][i + 1])
            y = 0.5 * (edges[1][j] + edges[1][j + 1])
            out.append(("shape", None, np.nan, int(k), x, y, ch, rms, lo, hi, n))
    tb = np.minimum((info["t_rel"].to_numpy() * N_TIME_BINS).astype(int), N_TIME_BINS - 1)
    for k, ch, rms, lo, hi, n in _rms_table(res, np.repeat(tb, n_s), trial, rng, n_boot):
        x = (k + 0.5) / N_TIME_BINS
        out.append(("time", None, np.nan, int(k), x, np.nan, ch, rms, lo, hi, n))
    cols = [
        "view",
        "gait",
        "frequency_hz",
        "bin",
        "x",
        "y",
        "channel",
        "rms",
        "band_lo",
        "band_hi",
        "n",
    ]
    return pd.DataFrame(out, columns=cols)


def systematic_gap(
    residual: np.ndarray, phase: np.ndarray, info: pd.DataFrame, halves: tuple
) -> tuple[float, float]:
    """Is the remaining residual systematic? Split-half agreement of its phase profile.

    ``residual`` (n_windows, n_samples, n_channels): every compared channel, the passive
    shape's included, since the gap it tests is measured on all of them (a model without
    the spokes' ringing leaves its error in r_p only). For every condition and channel,
    the mean residual per phase bin is computed on the windows of each half of the trials
    (``halves``: two arrays of trial ids); a model error repeats in both halves (positive
    correlation), noise does not. Returns the mean Fisher-z of those correlations and the
    one-sided p-value of a t-test over (condition, channel) pairs that it is > 0.
    """
    from scipy import stats

    zs = []
    n_ch = residual.shape[-1]
    cond = info["gait"].astype(str) + "|" + info["frequency_hz"].round(6).astype(str)
    pbin = _phase_bins(phase)
    for c in np.unique(cond):
        prof = []
        for h in halves:
            sel = (cond == c).to_numpy() & np.isin(info["trial_id"].to_numpy(), h)
            if not sel.any():
                break
            r, b = residual[sel].reshape(-1, n_ch), pbin[sel].reshape(-1)
            m = np.full((N_PHASE_BINS, n_ch), np.nan)
            for k in range(N_PHASE_BINS):
                hit = (b == k) & np.all(np.isfinite(r), axis=1)
                if hit.any():
                    m[k] = r[hit].mean(0)
            prof.append(m)
        if len(prof) < 2:
            continue
        for ch in range(n_ch):
            a, b2 = prof[0][:, ch], prof[1][:, ch]
            ok = np.isfinite(a) & np.isfinite(b2)
            if ok.sum() > 3 and a[ok].std() > 0 and b2[ok].std() > 0:
                rho = np.corrcoef(a[ok], b2[ok])[0, 1]
                zs.append(np.arctanh(np.clip(rho, -0.999, 0.999)))
    if len(zs) < 2:
        return float("nan"), 1.0
    zs = np.asarray(zs)
    return float(zs.mean()), float(stats.ttest_1samp(zs, 0.0, alternative="greater").pvalue)


def residual_correlations(
    samples: pd.DataFrame, residual: np.ndarray, windows_t: np.ndarray, info: pd.DataFrame
) -> pd.DataFrame:
    """Correlation of the remaining residual with measured signals.

    Signals: passive shape r_p and its rate, actuated shape rate, body acceleration
    (from the measured velocity), speed, time in the trial. Returns one row per
    (channel, signal): pearson r over the windows' samples, sorted by |r|.
    """
    sigs = [c for c in samples.columns if c.startswith(("rp_", "drp_", "dra_"))]
    sigs = [c for c in sigs if samples[c].notna().any()]
    frames = []
    for k, tid in enumerate(info["trial_id"].to_numpy()):
        tr = samples[samples["trial_id"] == tid]
        t = tr["t"].to_numpy()
        tt = windows_t[k]
        ok = np.isfinite(tt)
        idx = np.clip(np.searchsorted(t, tt[ok]), 0, len(t) - 1)
        block = tr.iloc[idx][sigs + ["vx", "vy", "wz"]].reset_index(drop=True)
        dt = np.gradient(t)[idx]
        for ch in ("vx", "vy", "wz"):
            block[f"acc_{ch}"] = np.gradient(tr[ch].to_numpy())[idx] / dt
        block["speed"] = np.hypot(block["vx"], block["vy"])
        block["t"] = t[idx]
        for c, ch in enumerate(CHANNELS):
            block[f"res_{ch}"] = residual[k, ok, c]
        frames.append(block)
    data = pd.concat(frames, ignore_index=True)
    signals = sigs + ["acc_vx", "acc_vy", "acc_wz", "speed", "t"]
    rows = []
    for ch in CHANNELS:
        r = data[f"res_{ch}"]
        for s in signals:
            x = data[s]
            ok = np.isfinite(r) & np.isfinite(x)
            if ok.sum() > 3 and r[ok].std() > 0 and x[ok].std() > 0:
                rows.append((ch, s, float(np.corrcoef(r[ok], x[ok])[0, 1])))
    out = pd.DataFrame(rows, columns=["channel", "signal", "r"])
    return out.reindex(out["r"].abs().sort_values(ascending=False).index).reset_index(drop=True)
