"""Replay: drive the simulator with each measured trial's own actuated shape r_a(t).

Cost is what shapes this module. A candidate fit needs the simulator's answer for many
parameter values on many trials, so the replay runs on short windows (a few cycles of
each trial), at a fixed number of samples per gait cycle (the quasi-static physics does
not need 100 Hz) but never coarser than `ReplaySettings.max_step_s` (the spoke markers'
ringing, compared through the passive shape, is excited by accelerations a coarse step
would smooth away), and stacks every window x configuration of one evaluation into one
simulator call per frame interval.

A window starts with a warm-up (flipper angles and the body-inertia state forget their
unknown initial values) and is scored after it. To compare like with like, the replay's
body velocity goes through the same differentiator as the measurement: the simulated
pose is interpolated back to the capture rate and differentiated with the
preprocessing version's own `Differentiator` (`Version.differentiator`, never a copy
of its settings); the replayed r_a is the measured one.

`medium_compaction` depends on the distance travelled since the start of the trial; a
window starting after distance d0 (measured, m) is replayed with the exactly equivalent
parameters normal_scale * (1 + c d0) and c / (1 + c d0) (adapter: the simulator starts
every trial at distance 0).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline
from scipy.signal import savgol_filter

from suds_exp.preprocess.params import DEFAULTS
from suds_exp.preprocess.rates import Differentiator
from suds_exp.robot import PASSIVE_ROLES
from suds_exp.sim.config import SimConfig
from suds_exp.sim.markers import (
    MARKER_NAMES,
    SPOKE_MARKERS,
    rigid_marker_positions,
    spoke_deflection,
)
from suds_exp.sim.mechanics import simulate_prescribed

CHANNELS = ("vx", "vy", "wz")


@dataclass(frozen=True)
class ReplaySettings:
    """How measured trials are cut into replay windows.

    Parameters
    ----------
    windows_per_trial : int
        Windows per trial, spread evenly over its length.
    cycles_per_window : float
        Scored length of each window, gait cycles.
    warmup_cycles : float
        Replayed but not scored before each window, gait cycles.
    samples_per_cycle : int
        Simulator steps per gait cycle (the decimation; 100 Hz capture at 1 Hz is 100).
    max_step_s : float
        Longest simulator step (s), whatever the gait frequency; 0: no limit. The spoke
        markers ring at ~5 Hz, excited by the body's and segments' accelerations; at 40
        steps per cycle a 1/3 Hz gait would step every 75 ms, the interpolated pose
        would lose that excitation and a replay with the true spoke gain would look
        worse than one without. 25 ms (8 steps per 5 Hz period) resolves it.
    solver_tol : float
        Scaled residual tolerance of the simulator's per-step solve during replay.
    ra_smooth_s : float
        Savitzky-Golay smoothing window (s, order `Differentiator.polyorder`) applied to
        the measured r_a before it drives the replay, against marker noise; 0 replays it
        as measured (the samples' r_a is already smoothed by the preprocessing).
    shape_window_s, shape_polyorder : float, int
        The preprocessing version's smoothing of the passive state (applied to the
        replayed passive state too; `settings_from_prep` takes them from the version).

    The differentiator is not a setting: `make_windows` takes the version's own.
    """

    windows_per_trial: int = 2
    cycles_per_window: float = 1.0
    warmup_cycles: float = 1.0
    samples_per_cycle: int = 40
    max_step_s: float = 0.025
    solver_tol: float = 1e-7
    ra_smooth_s: float = 0.0
    shape_window_s: float = DEFAULTS["shape_window_s"]
    shape_polyorder: int = DEFAULTS["shape_polyorder"]


@dataclass
class WindowGroup:
    """Windows sharing one simulator frame interval (same frequency).

    Arrays: ``phi`` (n, n_steps, 2) rad, decimated smoothed r_a from the warm-up start;
    ``measured`` (n, n_scored, 3) vx, vy mm/s, wz rad/s; ``phase`` (n, n_scored) rad;
    ``ra`` (n, n_scored, 2) rad; ``t`` (n, n_scored) s within the trial; ``d0`` (n,) m
    travelled before the window's replay starts.
    """

    dt: float
    step: int
    index: np.ndarray
    phi: np.ndarray
    measured: np.ndarray
    phase: np.ndarray
    ra: np.ndarray
    t: np.ndarray
    d0: np.ndarray
    n_fine: int
    score_from: int
    n_scored: int
    diff_frames: int
    ra_fine: np.ndarray | None = None


@dataclass
class WindowSet:
    """Replay windows over trials. ``trial_id`` (n_windows,), and groups by frame interval.

    ``info`` is a frame with one row per window: trial_id, gait, frequency_hz, t_start,
    t_rel (window centre over trial length, 0..1). ``differentiator`` is the one that
    made the measured rates; the replay's rates go through it too.
    """

    info: pd.DataFrame
    groups: list[WindowGroup]
    settings: ReplaySettings
    pca: object | None = None
    differentiator: Differentiator = field(default_factory=lambda: default_differentiator())

    @property
    def channels(self) -> tuple[str, ...]:
        """Compared channels: vx, vy, wz, then rp_1..rp_k when the passive shape is."""
        if self.pca is None:
            return CHANNELS
        return CHANNELS + tuple(f"rp_{i + 1}" for i in range(self.pca.n_components))

    @property
    def trial_id(self) -> np.ndarray:
        return self.info["trial_id"].to_numpy()

    def subset(self, trials) -> WindowSet:
        """The windows of the given trial ids only."""
        keep = np.isin(self.trial_id, np.asarray(list(trials)))
        new_index = np.cumsum(keep) - 1
        groups = []
        for g in self.groups:
            m = keep[g.index]
            if not m.any():
                continue
            groups.append(
                WindowGroup(
                    g.dt,
                    g.step,
                    new_index[g.index[m]],
                    g.phi[m],
                    g.measured[m],
                    g.phase[m],
                    g.ra[m],
                    g.t[m],
                    g.d0[m],
                    g.n_fine,
                    g.score_from,
                    g.n_scored,
                    g.diff_frames,
                    None if g.ra_fine is None else g.ra_fine[m],
                )
            )
        return WindowSet(
            self.info[keep].reset_index(drop=True),
            groups,
            self.settings,
            self.pca,
            self.differentiator,
        )


def default_differentiator() -> Differentiator:
    """The differentiator of a version made with the default parameters: what samples
    given without a store are taken to have been differentiated with."""
    return Differentiator.from_params(DEFAULTS)


def settings_from_prep(params: dict, **overrides) -> ReplaySettings:
    """Replay settings matching a preprocessing version's parameters (its smoothing of
    the passive state)."""
    return ReplaySettings(
        shape_window_s=float(params.get("shape_window_s", DEFAULTS["shape_window_s"])),
        shape_polyorder=int(params.get("shape_polyorder", DEFAULTS["shape_polyorder"])),
        **overrides,
    )


def _odd_window(window_s: float, dt: float, polyorder: int) -> int:
    w = max(int(round(window_s / dt)), polyorder + 2)
    return w + 1 - w % 2


def make_windows(
    samples: pd.DataFrame,
    settings: ReplaySettings | None = None,
    pca=None,
    differentiator: Differentiator | None = None,
) -> WindowSet:
    """Cut measured trials into replay windows.

    With ``pca`` (the preprocessing version's `PassivePCA`) the passive shape r_p is
    compared too: the replay computes the markers, their passive coordinates and r_p
    exactly as the preprocessing did, and both sides lose their mean over each window
    (a constant offset of the estimated segment origins is not physics).

    Parameters
    ----------
    samples : DataFrame
        Samples frame (`suds_exp.preprocess.load_samples`): trial_id, t (s), phase (rad),
        ra_1, ra_2 (rad), vx, vy (mm/s), wz (rad/s), gait, frequency_hz.
    settings : ReplaySettings, optional
    pca : PassivePCA, optional
    differentiator : Differentiator, optional
        The one that made the samples' rates (`Version.differentiator`); None: that of
        the default preprocessing parameters.
    """
    s = settings or ReplaySettings()
    diff = differentiator or default_differentiator()
    rows: list[dict] = []
    per_group: dict[tuple, list] = {}
    for trial_id, tr in samples.sort_values(["trial_id", "t"]).groupby("trial_id", sort=True):
        _cut_trial(int(trial_id), tr, s, diff, pca, rows, per_group)
    groups = [_window_group(key, items, pca) for key, items in per_group.items()]
    return WindowSet(pd.DataFrame(rows), groups, s, pca, diff)


def _trial_frequency(tr: pd.DataFrame, t: np.ndarray) -> tuple[float, bool] | None:
    """The trial's gait frequency (Hz) and whether the manifest gave it (else from its
    phase); None when neither gives a positive one."""
    freq = tr["frequency_hz"].iloc[0]
    known = freq is not None and bool(np.isfinite(freq)) and freq > 0
    if not known:
        # a capture without a manifest: the gait frequency from its phase
        ph = tr["phase"].to_numpy(float)
        freq = (ph[-1] - ph[0]) / (2 * np.pi * max(t[-1] - t[0], 1e-9))
        if not np.isfinite(freq) or freq <= 0:
            return None
    return float(freq), known


def _window_frames(s: ReplaySettings, diff: Differentiator, freq, known, dt_cap, n):
    """(step, differentiator window, warm-up, scored and total frames) of a window."""
    period_frames = 1.0 / (freq * dt_cap)
    step = max(1, int(round(period_frames / s.samples_per_cycle)))
    if s.max_step_s > 0:
        step = max(1, min(step, int(s.max_step_s / dt_cap + 1e-9)))
    # the window the preprocessing used: from the frequency it knew, if any
    sg = diff.window(1.0 / dt_cap, freq if known else None, n)
    half = sg // 2
    n_warm = int(round(s.warmup_cycles * period_frames / step)) * step
    n_score = int(round(s.cycles_per_window * period_frames))
    # the replay runs half a filter window past the scored end so the
    # differentiator sees the same neighbourhood as the measurement's did
    n_tail = int(np.ceil(half / step)) * step
    n_total = n_warm + n_score + n_tail
    n_total = int(np.ceil((n_total - 1) / step)) * step + 1
    return step, sg, n_warm, n_score, n_total


def _trial_signals(tr: pd.DataFrame, t, s: ReplaySettings, diff: Differentiator, pca, dt_cap):
    """r_a (rad) as measured and as driven (smoothed), the compared channels and the path
    length from the trial's start (m)."""
    ra = tr[["ra_1", "ra_2"]].to_numpy(float)
    ra_s = ra
    if s.ra_smooth_s > 0:
        w = min(_odd_window(s.ra_smooth_s, dt_cap, diff.polyorder), len(t) - 1 + len(t) % 2)
        ra_s = savgol_filter(ra, w, diff.polyorder, axis=0)
    meas = tr[list(CHANNELS)].to_numpy(float)
    speed = np.hypot(meas[:, 0], meas[:, 1])
    if pca is not None:
        meas = np.column_stack(
            [meas, tr[[f"rp_{i + 1}" for i in range(pca.n_components)]].to_numpy(float)]
        )
    # path length from the trial's start (mm -> m); before the first kept sample
    # the robot is assumed to have moved at its mean speed
    dist = (
        np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(t))])
        + np.nanmean(speed) * t[0]
    ) / 1000.0
    return ra, ra_s, meas, dist


def _cut_trial(trial_id, tr, s: ReplaySettings, diff, pca, rows: list, per_group: dict):
    """Append the windows of one trial: their info rows to ``rows``, their arrays to
    ``per_group`` under the key of their shape."""
    t = tr["t"].to_numpy(float)
    if len(t) < 8:
        return
    dt_cap = float(np.median(np.diff(t)))
    found = _trial_frequency(tr, t)
    if found is None:
        return
    freq, known = found
    step, sg, n_warm, n_score, n_total = _window_frames(s, diff, freq, known, dt_cap, len(t))
    if len(t) < n_total:
        return
    ra, ra_s, meas, dist = _trial_signals(tr, t, s, diff, pca, dt_cap)
    starts = np.linspace(0, len(t) - n_total, s.windows_per_trial + 2)[1:-1]
    if s.windows_per_trial == 1:
        starts = np.array([(len(t) - n_total) / 2])
    key = (round(dt_cap * step, 9), step, n_total, n_warm, n_score, sg)
    for a in np.round(starts).astype(int):
        sc = slice(a + n_warm, a + n_warm + n_score)
        g = per_group.setdefault(key, [])
        g.append(
            (
                len(rows),
                ra_s[a : a + n_total : step],
                meas[sc],
                tr["phase"].to_numpy(float)[sc],
                ra[sc],
                t[sc],
                dist[a],
                ra_s[a : a + n_total],
            )
        )
        rows.append(
            {
                "trial_id": trial_id,
                "gait": tr["gait"].iloc[0],
                "frequency_hz": freq,
                "t_start": float(t[a + n_warm]),
                "t_rel": float((t[sc][len(t[sc]) // 2] - t[0]) / max(t[-1] - t[0], 1e-9)),
            }
        )


def _window_group(key: tuple, items: list, pca) -> WindowGroup:
    """The windows of one shape (``key``) stacked into a `WindowGroup`."""
    dt, step, n_total, n_warm, n_score, sg = key
    idx, phi, meas, phase, ra, tt, d0, ra_fine = zip(*items, strict=True)
    meas = np.stack(meas)
    if pca is not None:
        meas[..., 3:] -= meas[..., 3:].mean(axis=1, keepdims=True)
    return WindowGroup(
        dt=dt,
        step=step,
        index=np.array(idx),
        phi=np.stack(phi),
        measured=meas,
        phase=np.stack(phase),
        ra=np.stack(ra),
        t=np.stack(tt),
        d0=np.array(d0),
        n_fine=n_total,
        score_from=n_warm,
        n_scored=n_score,
        diff_frames=sg,
        ra_fine=np.stack(ra_fine),
    )


def _window_config(cfg: SimConfig, d0_m: float, tol: float) -> SimConfig:
    """``cfg`` with the replay's solver tolerance and, for a window starting after d0_m
    (m), the equivalent compaction parameters. Only the changed parts are new objects
    (the rest is shared with ``cfg``, never modified): a fit replays thousands of
    windows and a deep copy of each configuration cost more than its parameters."""
    ef = cfg.effects
    c = ef.medium_compaction.rate_per_m
    if c > 0 and d0_m > 0:
        grow = 1.0 + c * d0_m
        ef = replace(
            ef,
            drag_anisotropy=replace(
                ef.drag_anisotropy, normal_scale=ef.drag_anisotropy.normal_scale * grow
            ),
            medium_compaction=replace(ef.medium_compaction, rate_per_m=c / grow),
        )
    return replace(cfg, solver=replace(cfg.solver, tol=tol), effects=ef)


def _window_configs(configs: list[SimConfig], d0: np.ndarray, tol: float) -> list[SimConfig]:
    """One configuration per (config, window), configs outermost; windows whose
    configuration does not depend on where they start share one object."""
    out = []
    for cfg in configs:
        if cfg.effects.medium_compaction.rate_per_m > 0:
            out += [_window_config(cfg, float(d), tol) for d in d0]
        else:
            out += [_window_config(cfg, 0.0, tol)] * len(d0)
    return out


def replay(windows: WindowSet, configs: list[SimConfig]) -> np.ndarray:
    """Simulated body velocity of every window under every configuration.

    Parameters
    ----------
    windows : WindowSet
    configs : list of n_configs SimConfig

    Returns
    -------
    array of shape (n_configs, n_windows, n_scored_max, n_channels)
        vx, vy (mm/s), wz (rad/s), body frame, through the measurement's differentiator,
        then (with a PCA) r_p minus its window mean (mm); NaN past a window's scored
        length. Channels: ``windows.channels``.
    """
    n_win = len(windows.info)
    n_max = max((g.n_scored for g in windows.groups), default=0)
    out = np.full((len(configs), n_win, n_max, len(windows.channels)), np.nan)
    s = windows.settings
    for g in windows.groups:
        n = len(g.index)
        batch_cfg = _window_configs(configs, g.d0, s.solver_tol)
        phi = np.tile(g.phi, (len(configs), 1, 1))
        sim = simulate_prescribed(phi, g.dt, batch_cfg)
        pose = sim["pose"]  # (n_cfg * n, n_steps, 3)
        coarse_t = np.arange(pose.shape[1]) * g.step
        fine_t = np.arange(g.n_fine)
        fine = CubicSpline(coarse_t, pose, axis=1)(fine_t)
        dt_cap = g.dt / g.step
        along_time = np.moveaxis(fine, 1, 0)
        rates = np.moveaxis(windows.differentiator(along_time, dt_cap, g.diff_frames), 0, 1)
        sc = slice(g.score_from, g.score_from + g.n_scored)
        heading = fine[:, sc, 2]
        c, sn = np.cos(heading), np.sin(heading)
        vx = c * rates[:, sc, 0] + sn * rates[:, sc, 1]
        vy = -sn * rates[:, sc, 0] + c * rates[:, sc, 1]
        vel = np.stack([vx, vy, rates[:, sc, 2]], axis=-1).reshape(len(configs), n, g.n_scored, 3)
        out[:, g.index, : g.n_scored, :3] = vel
        if windows.pca is not None:
            rp = _passive(windows, g, configs, fine, sim["flippers"], dt_cap, sc)[:, sc]
            rp = rp - rp.mean(axis=1, keepdims=True)
            out[:, g.index, : g.n_scored, 3:] = rp.reshape(len(configs), n, g.n_scored, -1)
    return out


def _passive(windows, g: WindowGroup, configs, pose_fine, flippers, dt_cap, scored) -> np.ndarray:
    """Replayed r_p, (n_configs * n_windows, n_fine, k) mm, the preprocessing's way:
    markers (with the spokes' oscillation) -> coordinates in the segment frames ->
    smoothing -> PCA projection. Exact on the frames of the slice ``scored`` (the
    smoothing's edge frames outside it are left unfitted)."""
    s = windows.settings
    n_b, n_fine = pose_fine.shape[:2]
    n_cfg = len(configs)
    n = n_b // n_cfg
    # flipper angles: linear between the simulator's (decimated) steps
    k = np.arange(n_fine) / g.step
    lo = np.minimum(np.floor(k).astype(int), flippers.shape[1] - 1)
    hi = np.minimum(lo + 1, flippers.shape[1] - 1)
    frac = (k - lo)[None, :, None]
    fl = flippers[:, lo] * (1 - frac) + flippers[:, hi] * frac
    phi = np.tile(g.ra_fine, (n_cfg, 1, 1))
    pos = rigid_marker_positions(
        configs[0], pose_fine.reshape(-1, 3), phi.reshape(-1, 2), fl.reshape(-1, 4)
    ).reshape(n_b, n_fine, len(MARKER_NAMES), 3)
    for i, cfg in enumerate(configs):
        if cfg.effects.spoke_oscillation.gain == 0:
            continue
        rows = slice(i * n, (i + 1) * n)
        for name in SPOKE_MARKERS:
            j = MARKER_NAMES.index(name)
            # every window of one configuration at once, time along the first axis (the
            # filter runs along it, each window's numbers as when filtered alone)
            base = pos[rows, :, j, :2].transpose(1, 0, 2)
            pos[rows, :, j, :2] += spoke_deflection(cfg, base, dt_cap).transpose(1, 0, 2)
    half = configs[0].geometry.middle_length_mm / 2
    x, y, th = pose_fine[..., 0], pose_fine[..., 1], pose_fine[..., 2]
    c, sn = np.cos(th), np.sin(th)
    frames = {
        "head": (x + c * half, y + sn * half, th + phi[..., 0]),
        "tail": (x - c * half, y - sn * half, th - phi[..., 1]),
    }
    cols = []
    for role, segment in PASSIVE_ROLES:
        ox, oy, heading = frames[segment]
        j = MARKER_NAMES.index(role)
        dx, dy = pos[..., j, 0] - ox, pos[..., j, 1] - oy
        ch, sh = np.cos(heading), np.sin(heading)
        cols += [ch * dx + sh * dy, -sh * dx + ch * dy]
    passive = np.stack(cols, axis=-1)
    if s.shape_window_s > 0:
        w = min(_odd_window(s.shape_window_s, dt_cap, s.shape_polyorder), n_fine - 1 + n_fine % 2)
        if w > s.shape_polyorder:
            # the polynomial edge fits (mode "interp") only set the first and last w // 2
            # frames, and cost more than the whole filter: skipped when none is scored
            inside = scored.start >= w // 2 and scored.stop <= n_fine - w // 2
            mode = "constant" if inside else "interp"
            passive = savgol_filter(passive, w, s.shape_polyorder, axis=1, mode=mode)
    return windows.pca.transform(passive.reshape(-1, 12)).reshape(n_b, n_fine, -1)


def measured(windows: WindowSet) -> np.ndarray:
    """Measured channels of every window, (n_windows, n_scored_max, n_channels), NaN
    padded (channels as `replay`)."""
    n_max = max((g.n_scored for g in windows.groups), default=0)
    out = np.full((len(windows.info), n_max, len(windows.channels)), np.nan)
    for g in windows.groups:
        out[g.index, : g.n_scored] = g.measured
    return out


def window_field(windows: WindowSet, name: str) -> np.ndarray:
    """A per-sample field (``phase``, ``t``, ``ra``) of every window, NaN padded."""
    n_max = max((g.n_scored for g in windows.groups), default=0)
    first = getattr(windows.groups[0], name)
    out = np.full((len(windows.info), n_max, *first.shape[2:]), np.nan)
    for g in windows.groups:
        out[g.index, : g.n_scored] = getattr(g, name)
    return out
