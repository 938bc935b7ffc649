"""The swimmer's mechanics: element tables from the geometry, and the public batched
simulation of prescribed joint trajectories (the single physics entry point).

`simulate_prescribed` is what both the gait path (command -> actuator -> physics) and the
discrepancy workflow (replay measured phi1, phi2) call.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from suds_exp.errors import ConfigError
from suds_exp.sim import rft
from suds_exp.sim.bed import draw_bed, draw_grains
from suds_exp.sim.config import SimConfig
from suds_exp.sim.kernel_params import kernel_layout, kernel_values


@dataclass(frozen=True)
class ElementTable:
    """RFT elements of the robot, in units of L_ref = middle segment length.

    part (n_el,): 0 head, 1 middle, 2 tail, 3 + i flipper i; s (n_el,): element centre
    along its segment axis in the segment frame (origin at the joint), or distance from
    the hinge for flippers; w (n_el,): length x depth / (L_ref x segment depth).
    Flipper i (0..3 = flipper_1..flipper_4): segment (0 head, 2 tail), hinge (hx, hy) in
    the segment frame, side +1 left (+Y), -1 right.
    """

    part: np.ndarray
    s: np.ndarray
    w: np.ndarray
    half_mid: float
    fl_seg: np.ndarray
    fl_hx: np.ndarray
    fl_hy: np.ndarray
    fl_side: np.ndarray
    l_ref: float

    @property
    def n_processes(self) -> int:
        """Grain-contact processes of the kernel: one per element and one per part."""
        return len(self.part) + rft.N_PARTS

    def kernel_args(self) -> tuple:
        return (
            self.part,
            self.s,
            self.w,
            self.half_mid,
            self.fl_seg,
            self.fl_hx,
            self.fl_hy,
            self.fl_side,
        )


def _midpoints(lo: float, hi: float, n: int) -> np.ndarray:
    edges = np.linspace(lo, hi, n + 1)
    return 0.5 * (edges[:-1] + edges[1:])


def element_table(cfg: SimConfig) -> ElementTable:
    """Discretise segments and flippers of `cfg.geometry` into RFT elements."""
    g = cfg.geometry
    L = g.middle_length_mm
    n, nf = g.elements_per_segment, g.elements_per_flipper
    parts, s, w = [], [], []
    for part, lo, hi in (
        (0, 0.0, g.head_length_mm),
        (1, -L / 2, L / 2),
        (2, -g.tail_length_mm, 0.0),
    ):
        parts.append(np.full(n, part))
        s.append(_midpoints(lo, hi, n) / L)
        w.append(np.full(n, (hi - lo) / n / L))
    # head flippers hinge at +head_hinge along the head; tail ones at -tail_hinge
    fl_seg = np.array([0, 0, 2, 2], dtype=np.int64)
    fl_hx = np.array([g.head_hinge_mm, g.head_hinge_mm, -g.tail_hinge_mm, -g.tail_hinge_mm]) / L
    fl_side = np.array([1.0, -1.0, 1.0, -1.0])
    fl_hy = fl_side * (g.segment_width_mm / 2) / L
    depth_ratio = g.flipper_depth_mm / g.segment_depth_mm
    for i in range(4):
        parts.append(np.full(nf, 3 + i))
        s.append(_midpoints(0.0, g.flipper_length_mm, nf) / L)
        w.append(np.full(nf, g.flipper_length_mm / nf / L * depth_ratio))
    return ElementTable(
        part=np.concatenate(parts).astype(np.int64),
        s=np.concatenate(s),
        w=np.concatenate(w),
        half_mid=0.5,
        fl_seg=fl_seg,
        fl_hx=fl_hx,
        fl_hy=fl_hy,
        fl_side=fl_side,
        l_ref=L,
    )


def pack_params(cfg: SimConfig) -> np.ndarray:
    """Kernel parameter vector (n_params,) of one configuration (scaled units), laid out
    by `kernel_params.kernel_layout` (the solver's ``P_*`` indices)."""
    layout = kernel_layout()
    p = np.zeros(sum(n for _, n in layout.values()))
    for key, value in kernel_values(cfg).items():
        start, n = layout[key]
        p[start : start + n] = value
    return p


def residual_units(cfg: SimConfig) -> tuple[float, float]:
    """(N, N mm) represented by one unit of the solver's scaled residual."""
    g = cfg.geometry
    force = cfg.medium.stress_scale_n_per_mm2 * g.segment_depth_mm * g.middle_length_mm
    return force, force * g.middle_length_mm


def _same_geometry(configs: list[SimConfig]) -> None:
    first = configs[0].geometry
    for c in configs[1:]:
        if c.geometry != first:
            raise ConfigError("simulate_prescribed: all configs of one batch must share geometry")


def simulate_prescribed(
    phi: np.ndarray,
    dt: float,
    config: SimConfig | list[SimConfig] | None = None,
    pose0: np.ndarray | None = None,
    flippers0: np.ndarray | None = None,
    n_frames: np.ndarray | None = None,
    commanded: bool = False,
    trial_seeds: list | None = None,
) -> dict[str, np.ndarray]:
    """Simulate a batch of trials driven by prescribed joint angles (or servo commands).

    Parameters
    ----------
    phi : array of shape (n_trials, n_frames, 2) or (n_frames, 2), rad
        phi1 (head joint), phi2 (tail joint) sampled every `dt` seconds (e.g. measured).
    dt : float, s
        Sample interval (0.01 at 100 Hz); `config.solver.substeps` solves per interval,
        phi linearly interpolated between samples.
    config : SimConfig or list of n_trials SimConfig (same geometry), default nominal
        Physics and effects (each trial may have its own effect parameters).
    pose0 : array of shape (n_trials, 3), optional
        Initial world pose x, y (mm), theta (rad) of the body frame; default zeros.
    flippers0 : array of shape (n_trials, 4), optional
        Initial flipper angles (rad, 0 = closed); default closed.
    n_frames : int array of shape (n_trials,), optional
        Valid frames of each trial when trials of different lengths are padded.
    commanded : bool
        False (default): `phi` are the joint angles (e.g. measured), followed exactly.
        True: `phi` is the servo command; with the `servo` effect on, the joints follow
        it under the medium's load (returned in ``phi``).
    trial_seeds : list of n_trials int tuples, optional
        Entropy of each trial's bed (`bed_heterogeneity`, `bed_packing`); None gives
        the mean bed (uniform), all a replay of measured angles can know.

    Returns
    -------
    dict of arrays (n_trials, n_frames[, k]); frames past a trial's length are NaN:
        ``pose`` (x, y mm, theta rad; world), ``vel`` (vx, vy mm/s, wz rad/s; body frame,
        centred on each frame), ``flippers`` (4, rad), ``phi`` (2, rad, realised joint angles),
        ``residual`` (max scaled force/torque residual of the solves ending at each frame,
        see `residual_units`), ``iterations`` and ``continuations`` (n_trials,).
    """
    phi, single = _as_batch(phi)
    n_trials, n_max = phi.shape[:2]
    if not dt > 0:
        raise ConfigError(f"dt: expected a positive sample interval in s, got {dt}")
    configs = _configs(config, n_trials)
    table = element_table(configs[0])
    prm = _trial_params(configs, commanded, trial_seeds)
    lengths = _lengths(phi, n_frames)
    p0, a0 = _initial_state(pose0, flippers0, n_trials)
    bed_modes, bed_scale = _beds(configs, trial_seeds)
    grains = np.stack(
        [
            draw_grains(c, None if trial_seeds is None else trial_seeds[k], table.n_processes)
            for k, c in enumerate(configs)
        ]
    )
    out = _empty_outputs(n_trials, n_max)
    rft.run_trials(
        np.ascontiguousarray(phi),
        lengths,
        p0,
        a0,
        prm,
        *table.kernel_args(),
        float(dt),
        bed_modes,
        bed_scale,
        grains,
        *(out[k] for k in ("pose", "vel", "flippers", "phi", "residual")),
        out["iterations"],
        out["continuations"],
    )
    if single:
        out = {k: v[0] for k, v in out.items()}
    return out


def _trial_params(configs: list[SimConfig], commanded: bool, trial_seeds) -> np.ndarray:
    """The kernel's parameter rows (n_trials, n_params) of `configs`, as the drive needs."""
    prm = np.stack([pack_params(c) for c in configs])
    if not commanded:
        # angles are followed exactly, whatever the servo's settings
        prm[:, rft.P_SGAIN] = 0.0
    if trial_seeds is None:
        # a replay cannot know the grains a trial met: it sees the mean medium
        prm[:, rft.P_GSIG] = 0.0
    return prm


def _empty_outputs(n_trials: int, n_max: int) -> dict[str, np.ndarray]:
    """`simulate_prescribed`'s result arrays, NaN (counts zero) until the kernel fills them."""
    return {
        "pose": np.full((n_trials, n_max, 3), np.nan),
        "vel": np.full((n_trials, n_max, 3), np.nan),
        "flippers": np.full((n_trials, n_max, 4), np.nan),
        "phi": np.full((n_trials, n_max, 2), np.nan),
        "residual": np.full((n_trials, n_max), np.nan),
        "iterations": np.zeros(n_trials, dtype=np.int64),
        "continuations": np.zeros(n_trials, dtype=np.int64),
    }


def _as_batch(phi) -> tuple[np.ndarray, bool]:
    """phi as (n_trials, n_frames, 2) and whether one trial (n_frames, 2) was given."""
    phi = np.asarray(phi, dtype=float)
    single = phi.ndim == 2
    if single:
        phi = phi[None]
    if phi.ndim != 3 or phi.shape[2] != 2:
        raise ConfigError(f"phi: expected shape (n_trials, n_frames, 2), got {phi.shape}")
    return phi, single


def _configs(config, n_trials: int) -> list[SimConfig]:
    """One configuration per trial, all of the same geometry."""
    if config is None:
        configs = [SimConfig()] * n_trials
    elif isinstance(config, list | tuple):
        configs = list(config)
    else:
        configs = [config] * n_trials
    if len(configs) != n_trials:
        raise ConfigError(f"config: got {len(configs)} configs for {n_trials} trials")
    _same_geometry(configs)
    return configs


def _lengths(phi: np.ndarray, n_frames) -> np.ndarray:
    """Valid frames per trial (n_trials,), checked against phi's finite samples."""
    n_trials, n_max = phi.shape[:2]
    lengths = (
        np.full(n_trials, n_max, dtype=np.int64)
        if n_frames is None
        else np.asarray(n_frames, dtype=np.int64).reshape(n_trials)
    )
    if lengths.min(initial=1) < 1 or lengths.max(initial=0) > n_max:
        raise ConfigError("n_frames: each trial needs 1..n_frames samples")
    for k in range(n_trials):
        if not np.all(np.isfinite(phi[k, : lengths[k]])):
            raise ConfigError(f"phi: trial {k} has non-finite joint angles")
    return lengths


def _initial_state(pose0, flippers0, n_trials: int) -> tuple[np.ndarray, np.ndarray]:
    """Initial poses (n_trials, 3) mm, rad and flipper angles (n_trials, 4) rad."""
    try:
        p0 = np.broadcast_to(
            np.zeros(3) if pose0 is None else np.asarray(pose0, float), (n_trials, 3)
        ).copy()
        a0 = np.broadcast_to(
            np.zeros(4) if flippers0 is None else np.asarray(flippers0, float), (n_trials, 4)
        ).copy()
    except ValueError:
        raise ConfigError(
            "pose0 / flippers0: expected shapes (n_trials, 3) / (n_trials, 4) or one row"
        ) from None
    return p0, a0


def _beds(configs: list[SimConfig], trial_seeds) -> tuple[np.ndarray, np.ndarray]:
    """Each trial's bed: random modes (n_trials, n_modes, 4) and packing factor (n_trials,)."""
    if trial_seeds is not None and len(trial_seeds) != len(configs):
        raise ConfigError(f"trial_seeds: got {len(trial_seeds)} seeds for {len(configs)} trials")
    beds = [
        draw_bed(c, None if trial_seeds is None else trial_seeds[k]) for k, c in enumerate(configs)
    ]
    return np.stack([b[0] for b in beds]), np.array([b[1] for b in beds])
