"""Phaser benchmark: our `suds_exp.preprocess.Phaser` against the authors' reference code,
both trained on 3 trials and applied to 3 others whose true phase is known.

Usage::

    .venv/bin/python benchmarks/phaser.py [--json] [--seed 0]

Cases (each: error to truth of both estimators, and their ratio ours / reference):

- ``gait-2ch@F``: our default input, the smoothed r_a = (ra_1, ra_2) of the default
  preprocessing of simulated trials of gait D+ at F Hz (true phase: the commanded one);
- ``gait-4ch@F``: a 4-D gait with flippers, (ra_1, ra_2, rp_1, rp_2) of the same trials;
- ``relax-2ch``, ``relax-4ch``: a relaxation oscillator (the van der Pol limit cycle,
  mu = 4, run at a drifting, diffusing phase that is the truth) seen through 2 or 4
  channels with unequal measurement noise, 100 frames a cycle.

Error: RMS over the test trials' frames of the wrapped phase difference to the truth,
after removing one constant offset per trial (the phase zero is a Poincare section, not
the truth's zero). Both estimators use Fourier order 10 and the same Poincare section
(channel 0 crossing its training mean upwards). Done when ``ratio <= 1.10`` on every case.

The reference below is a port to Python 3 of ``phaser.py`` (2015) of
https://github.com/sheim/phaser (S. Revzen, S. Wilshin; GPL-3.0; cite Revzen &
Guckenheimer, Phys. Rev. E 78, 051907, 2008), kept here for this comparison only; the
library's Phaser is written independently from the paper. The port keeps the reference's
arithmetic, including its z-scoring by the square root of the standard deviation of the
second differences and its phasor projection on two principal components.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.signal import hilbert

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from suds_exp.preprocess import Phaser, load_samples, preprocess  # noqa: E402
from suds_exp.preprocess.truth import truth_path  # noqa: E402
from suds_exp.sim.commands import simulate_command  # noqa: E402
from suds_exp.store import Store  # noqa: E402

ORDER = 10
TWO_PI = 2 * np.pi


# == port of the reference (sheim/phaser, phaser.py, 2015), benchmark only ================
class RefFourierSeries:
    """Port of the reference's ``FourierSeries`` (fit, val, integrate, weighted sum)."""

    def fit(self, order, ph, data):
        phi = np.reshape(np.mod(ph + np.pi, TWO_PI) - np.pi, (1, ph.size))
        idx = np.argsort(phi).flatten()
        dat = np.c_[data.take(idx, axis=-1), data[:, idx[0]]]
        phi = np.concatenate((phi.take(idx), [phi.flat[idx[0]] + TWO_PI]))
        dphi = np.diff(phi)
        self.m = np.sum((dat[:, :-1] + dat[:, 1:]) * 0.5 * dphi[None, :], axis=1) / (
            phi.max() - phi.min()
        )
        dat = (dat.T - self.m).T
        order = int(order)
        om = np.zeros(2 * order)
        om[::2] = np.arange(1, order + 1)
        om[1::2] = -om[::2]
        self.om = om.reshape(1, 2 * order)
        zd = (dat[:, 1:] + dat[:, :-1]) / (2.0 * TWO_PI) * dphi
        th = self.om.T * (phi[1:] - dphi / 2)
        self.coef = np.exp(-1j * th) @ zd.T
        return self

    def val(self, phi):
        phi = np.asarray(phi).reshape(-1, 1)
        return np.exp(1j * phi * self.om) @ self.coef + self.m

    def integrate(self, z0=0):
        self.m = np.zeros_like(self.m) + z0
        self.coef = -1j * self.coef / self.om.T
        return self

    @staticmethod
    def big_sum(fts, wgt):
        out = RefFourierSeries()
        out.coef = sum(w * f.coef for f, w in zip(fts, wgt, strict=True))
        out.m = sum(w * f.m for f, w in zip(fts, wgt, strict=True))
        out.om = fts[0].om
        return out


def _ref_angle_up(zeta):
    th = np.unwrap(np.angle(zeta))
    bad = th[:, 0] > th[:, -1]
    th[bad, :] = -th[bad, :]
    return th


def _ref_slice(x, s):
    idx = np.flatnonzero((s[1:] > 0) & (s[:-1] <= 0))
    idx = idx[idx < x.shape[1]]
    w_before, w_after = np.abs(s[idx])[None, :], np.abs(s[idx + 1])[None, :]
    return (x[:, idx] * w_after + x[:, idx + 1] * w_before) / (w_before + w_after), idx


def _ref_trim_cycle(zeta, y):
    ph = _ref_angle_up(zeta)
    n_cyc = np.abs(ph[:, -1] - ph[:, 0]) / TWO_PI
    cycl = int(np.ceil(zeta.shape[1] / n_cyc.max()))
    if np.any(n_cyc < 7) or n_cyc.max() - n_cyc.min() > 2:
        warnings.warn("reference: trial too short or channels disagree; not trimmed", stacklevel=2)
        return cycl, zeta, y
    return cycl, zeta[:, cycl:-cycl], y[:, cycl:-cycl]


def _ref_series_correction(zetas, order):
    proto = []
    for zeta in zetas:
        theta = _ref_angle_up(zeta)
        t = np.linspace(0, 1, zeta.shape[1])
        d_theta, dt = np.diff(theta, 1), np.diff(t)
        th = (theta[:, 1:] + theta[:, :-1]) / 2.0
        per = []
        for ki in range(zeta.shape[0]):
            row = th[ki].reshape(1, -1)
            rate = RefFourierSeries().fit(order * 2, row, d_theta[ki].reshape(1, -1) / dt)
            rate.coef, rate.m = rate.coef / rate.m, np.array([1.0])
            inv = RefFourierSeries().fit(order, row, 1 / rate.val(row).T)
            inv.coef, inv.m = inv.coef / inv.m, np.array([1.0])
            per.append(inv.integrate())
        proto.append(per)
    # the reference weighs trials by zeta.shape[0] (the number of channels): equal weights
    wgt = np.full(len(zetas), 1.0 / len(zetas))
    return [RefFourierSeries.big_sum([p[ki] for p in proto], wgt) for ki in range(len(proto[0]))]


class ReferencePhaser:
    """Port of the reference's ``Phaser`` (train and eval); data as (n_channels, n_frames)."""

    def __init__(self, trials, order, psecfunc):
        self.psf = psecfunc
        y = [np.asarray(t, dtype=float) for t in trials]
        pooled = np.hstack(y)
        # ZScore.fromData: "variance" taken as the std of the second differences
        self.y0 = np.nanmean(pooled, 1)
        self.S = np.diag(1 / np.sqrt(np.nanstd(np.diff(pooled, n=2, axis=1), axis=1)))
        zetas, svm, svv = [], [], []
        for k in range(len(y)):
            zeta = hilbert(self.zscore(y[k]))
            _, zeta, y[k] = _ref_trim_cycle(zeta, y[k])
            sv, idx = _ref_slice(zeta, self.psf(y[k]))
            if idx.size == 0:
                raise RuntimeError("reference: Poincare section is empty")
            zetas.append(zeta)
            svm.append(np.nanmean(sv, 1))
            svv.append(np.var(sv, 1) * sv.shape[1] / (sv.shape[1] - 1))
        svm, svv = np.stack(svm, 1), np.stack(svv, 1)
        # computeOffset
        svv = svv / svv.sum(1, keepdims=True)
        mangle = np.sum(svm * svv, 1)
        self.mangle = (np.conj(mangle) / np.abs(mangle)).reshape(-1, 1)
        ofs = np.angle(np.nanmean(self.mangle * svm, 0))
        zetas = [self.mangle * np.exp(-1j * ofs[k]) * z for k, z in enumerate(zetas)]
        rho = np.mean([np.nanmean(np.abs(z), 1) for z in zetas], axis=0).reshape(-1, 1)
        self.P_k = _ref_series_correction(zetas, order)
        q = []
        for z in zetas:
            th = _ref_angle_up(z)
            p = np.stack([self._corrected(th, ki) for ki in range(th.shape[0])])
            q.append(np.vstack([np.cos(p) * rho, np.sin(p) * rho]))
        w = np.hstack(q)
        w = w - np.nanmean(w, 1)[:, None]
        pc = np.linalg.svd(w, full_matrices=False)[0]
        self.prj = (pc[:, 0] + 1j * pc[:, 1]).reshape(-1, 1)
        self.P = _ref_series_correction([self.prj.T @ qk for qk in q], order)[0]

    def zscore(self, y):
        return self.S @ (y - self.y0.reshape(-1, 1))

    def _corrected(self, th, ki):
        p = self.P_k[ki].val(th[ki]).T[0] + th[ki]
        return p.real  # the series of a real function: imaginary part is rounding

    def __call__(self, dat):
        p0 = self.psf(dat)
        zeta = self.mangle * hilbert(self.zscore(dat))
        z0, _ = _ref_slice(zeta, p0)
        ofs = np.exp(-1j * np.angle(np.nanmean(z0, axis=1)))
        th = _ref_angle_up(zeta * ofs[:, None])
        p = np.stack([self._corrected(th, ki) for ki in range(th.shape[0])])
        rho = np.nanmean(np.abs(zeta), 1).reshape(-1, 1)
        ph = _ref_angle_up(self.prj.T @ np.vstack([np.cos(p) * rho, np.sin(p) * rho]))
        phi = np.real(ph + self.P.val(ph).T)[0]
        i = np.flatnonzero((p0[1:] > 0) & (p0[:-1] <= 0))
        at = (p0[i + 1] * np.exp(1j * phi[i + 1]) - p0[i] * np.exp(1j * phi[i])) / (
            p0[i + 1] - p0[i]
        )
        return phi - np.angle(np.sum(at))


# == cases ===================================================================================
def _section(mean0: float):
    return lambda x: x[0] - mean0


def phase_error(estimates: list[np.ndarray], truths: list[np.ndarray]) -> float:
    """Pooled RMS (rad) of wrapped estimate - truth, one constant offset removed per trial."""
    parts = []
    for est, true in zip(estimates, truths, strict=True):
        d = np.angle(np.exp(1j * (est - true)))
        d = np.angle(np.exp(1j * (d - np.angle(np.mean(np.exp(1j * d))))))
        parts.append(d)
    return float(np.sqrt(np.mean(np.square(np.concatenate(parts)))))


def compare(train: list[np.ndarray], test: list[np.ndarray], truth: list[np.ndarray]) -> dict:
    """Both estimators on (n_frames, n_channels) records; errors (rad) and ratio."""
    ours = Phaser(order=ORDER).fit(train)
    mean0 = float(np.concatenate(train)[:, 0].mean())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = ReferencePhaser([x.T for x in train], ORDER, _section(mean0))
    e_ours = phase_error([ours.transform(x) for x in test], truth)
    e_ref = phase_error([ref(x.T) for x in test], truth)
    return {
        "channels": train[0].shape[1],
        "ours_rad": e_ours,
        "reference_rad": e_ref,
        "ratio": e_ours / e_ref,
        "weights": [round(float(w), 3) for w in ours.weights_],
    }


def gait_cases(seed: int, frequencies=(1 / 3, 0.5, 1.0)) -> dict[str, dict]:
    """Simulated D+ trials, default preprocessing: the 2- and 4-channel cases per frequency."""
    out = {}
    with tempfile.TemporaryDirectory(prefix="suds-phaser-bench-") as tmp:
        store = Store(Path(tmp) / "bench.duckdb")
        freqs = ",".join(f"{f:g}" for f in frequencies)
        simulate_command(
            Path(tmp) / "data", gaits="D+", freqs=freqs, repeats=6, cycles="12:16",
            seed=seed, store=store,
        )  # fmt: skip
        preprocess(store, progress=False)
        samples = load_samples(store, 1)
        files = store.query_df("SELECT id, source_file FROM trials")
        import pandas as pd

        for f in frequencies:
            ids = sorted(samples.trial_id[np.isclose(samples.frequency_hz, f)].unique())
            chans, truths = {2: [], 4: []}, []
            for tid in ids:
                s = samples[samples.trial_id == tid]
                truth = pd.read_parquet(truth_path(files.source_file[files.id == tid].iloc[0]))
                truths.append(truth.phase_cmd.to_numpy())
                chans[2].append(s[["ra_1", "ra_2"]].to_numpy())
                chans[4].append(s[["ra_1", "ra_2", "rp_1", "rp_2"]].to_numpy())
            for m in (2, 4):
                out[f"gait-{m}ch@{f:.3g}Hz"] = compare(chans[m][:3], chans[m][3:6], truths[3:6])
    return out


def _limit_cycle(mu: float = 4.0, n: int = 2000) -> np.ndarray:
    """One period of the van der Pol limit cycle at uniform time, (n, 2): x, dx/dt."""

    def f(_, s):
        return [s[1], mu * (1 - s[0] ** 2) * s[1] - s[0]]

    warm = solve_ivp(f, (0, 200), [2.0, 0.0], rtol=1e-10, atol=1e-10)
    s0 = warm.y[:, -1]
    # one period: from an upward crossing of x = 0 to the next
    ev = lambda _, s: s[0]  # noqa: E731
    ev.direction = 1
    run = solve_ivp(f, (0, 60), s0, events=ev, rtol=1e-10, atol=1e-10, dense_output=True)
    t0, t1 = run.t_events[0][:2]
    return run.sol(np.linspace(t0, t1, n, endpoint=False)).T


def relaxation_cases(seed: int) -> dict[str, dict]:
    """Van der Pol waveforms at a known, drifting, diffusing phase; unequal channel noise."""
    cycle = _limit_cycle()
    scaled = cycle / cycle.std(axis=0)
    rng = np.random.default_rng(seed)
    records, truths = [], []
    for _ in range(6):
        n = int(rng.integers(1500, 2500))  # 15-25 cycles at 100 frames a cycle
        theta = (
            TWO_PI * np.arange(n) / 100
            + 0.3 * np.sin(TWO_PI * np.arange(n) / 1700 + rng.uniform(0, TWO_PI))
            + np.cumsum(rng.normal(0, 0.01, n))
            + rng.uniform(0, TWO_PI)
        )
        at = (np.mod(theta, TWO_PI) / TWO_PI * len(cycle)).astype(int) % len(cycle)
        x, v = scaled[at, 0], scaled[at, 1]
        clean = np.column_stack([x, v, x + 0.5 * v, np.tanh(2 * x) - 0.3 * v])
        records.append(clean)
        truths.append(theta)
    noise = np.array([0.05, 0.4, 0.15, 0.8])
    noisy = [r + rng.normal(0, 1, r.shape) * noise for r in records]
    out = {}
    for m in (2, 4):
        x = [r[:, :m] for r in noisy]
        out[f"relax-{m}ch"] = compare(x[:3], x[3:], truths[3:])
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    cases = {**gait_cases(args.seed), **relaxation_cases(args.seed)}
    if args.json:
        print(json.dumps(cases, indent=1))
        return
    print(f"{'case':<16} {'ours rad':>9} {'ref rad':>9} {'ratio':>6}  weights")
    for name, c in cases.items():
        print(
            f"{name:<16} {c['ours_rad']:9.4f} {c['reference_rad']:9.4f} {c['ratio']:6.2f}  "
            f"{c['weights']}"
        )
    worst = max(c["ratio"] for c in cases.values())
    print(f"worst ratio ours/reference: {worst:.2f} (target <= 1.10)")


if __name__ == "__main__":
    main()
