"""The bed of beans as a random resistance field, drawn per trial.

The field multiplies every RFT element's drag at the element's world position:
``scale * exp(sigma * g(x, y) - sigma^2 / 2)``, with g a unit-variance Gaussian field of
Gaussian covariance exp(-r^2 / (2 l^2)) built from `N_MODES` random Fourier modes
(Rahimi & Recht 2007): g = sqrt(2 / N) sum cos(k . x + phase), k ~ N(0, I / l^2). The
multiplier's mean is 1 and its coefficient of variation `spatial_cv`; `scale` is the
trial's log-normal packing factor (mean 1, CV `trial_cv`).
"""

from __future__ import annotations

import math

import numpy as np

from suds_exp.sim.config import SimConfig

N_MODES = 32


def draw_bed(cfg: SimConfig, entropy: tuple[int, ...] | None) -> tuple[np.ndarray, float]:
    """(modes (N_MODES, 4): kx, ky (1/mm), phase (rad), amplitude; scale) of one trial.

    ``entropy`` None gives the mean bed (no modes, scale 1): what a replay of measured
    joint angles simulates, since it cannot know the trial's bed.
    """
    modes = np.zeros((2 * N_MODES, 4))
    if entropy is None:
        return modes, 1.0
    rng = np.random.default_rng(np.random.SeedSequence(tuple(entropy) + (3,)))
    het, pack = cfg.effects.bed_heterogeneity, cfg.effects.bed_packing
    # draw every number whatever the settings, so one effect's value never shifts the
    # other's random numbers
    k = rng.normal(size=(N_MODES, 2)) / het.correlation_mm
    phase = rng.uniform(0.0, 2 * math.pi, N_MODES)
    z = float(rng.normal())
    sigma = math.sqrt(math.log1p(het.spatial_cv**2))
    modes[:N_MODES, :2] = k
    modes[:N_MODES, 2] = phase
    modes[:N_MODES, 3] = sigma * math.sqrt(2.0 / N_MODES)
    sig_t = math.sqrt(math.log1p(pack.trial_cv**2))
    # the immersion depth's field: its own stream, so the other fields keep their numbers
    dep = cfg.effects.bed_depth
    rng_d = np.random.default_rng(np.random.SeedSequence(tuple(entropy) + (6,)))
    modes[N_MODES:, :2] = rng_d.normal(size=(N_MODES, 2)) / dep.correlation_mm
    modes[N_MODES:, 2] = rng_d.uniform(0.0, 2 * math.pi, N_MODES)
    modes[N_MODES:, 3] = math.sqrt(math.log1p(dep.cv**2)) * math.sqrt(2.0 / N_MODES)
    return modes, math.exp(sig_t * z - 0.5 * sig_t**2)


def bed_multiplier(
    modes: np.ndarray, scale: float, xy: np.ndarray, body_xy: np.ndarray | None = None
) -> np.ndarray:
    """Resistance multiplier at world points xy (..., 2), mm (the kernel's formula): the
    packing ``scale``, the local field (modes' first half) at xy and, given the body's
    position ``body_xy`` (2,) mm, the immersion factor of the depth field (second half)."""
    xy = np.asarray(xy, dtype=float)
    out = scale * _lognormal_field(modes[:N_MODES], xy)
    if body_xy is not None:
        out = out * _lognormal_field(modes[N_MODES:], np.asarray(body_xy, dtype=float))
    return out


def _lognormal_field(modes: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """exp(g - var(g) / 2) of the random Fourier field of ``modes`` at points xy (..., 2)."""
    arg = xy[..., None, 0] * modes[:, 0] + xy[..., None, 1] * modes[:, 1] + modes[:, 2]
    g = (modes[:, 3] * np.cos(arg)).sum(axis=-1)
    # sum of amp^2 / 2 is the variance of g; subtracting half of it makes the mean 1
    half_var = 0.25 * float((modes[:, 3] ** 2).sum())
    return np.exp(g - half_var)


#: Random Fourier modes of each grain-contact process (`grain_contacts`).
N_GRAIN_MODES = 12


def draw_grains(cfg: SimConfig, entropy: tuple[int, ...] | None, n_processes: int) -> np.ndarray:
    """Random modes (n_processes, N_GRAIN_MODES, 2) of one trial's grain contacts:
    wavenumber (per middle-segment length of slip) and phase of unit Gaussian processes
    of slip distance with Gaussian correlation over ``correlation_mm``, one per RFT
    element and one per part (see `rft._grain_weights`). ``entropy`` None (a replay,
    which cannot know the grains) gives zeros; the kernel then leaves the drag as is
    because a replay also switches the effect off."""
    modes = np.zeros((n_processes, N_GRAIN_MODES, 2))
    if entropy is None:
        return modes
    rng = np.random.default_rng(np.random.SeedSequence(tuple(entropy) + (5,)))
    ell = cfg.effects.grain_contacts.correlation_mm / cfg.geometry.middle_length_mm
    modes[..., 0] = rng.normal(size=(n_processes, N_GRAIN_MODES)) / ell
    modes[..., 1] = rng.uniform(0.0, 2 * math.pi, (n_processes, N_GRAIN_MODES))
    return modes
