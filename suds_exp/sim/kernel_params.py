"""The compiled solver's packed parameter vector: the slots of a `SimConfig` (the medium,
the hinges and the solver settings, then each registered effect's, `effect_params.EFFECTS`)
and their layout, which gives `sim/forces.py` its ``P_*`` indices and
`mechanics.pack_params` its places.

Apart from `effect_params` because the slots are read from a whole `SimConfig`, which is
itself built from the effects' declarations.
"""

from __future__ import annotations

import math
from functools import cache

from suds_exp.sim.config import SimConfig
from suds_exp.sim.effect_params import EFFECTS, KernelUnits, effect_slots


def kernel_units(cfg: SimConfig) -> KernelUnits:
    """The solver's scales for a `SimConfig` (its geometry and medium)."""
    g = cfg.geometry
    force = cfg.medium.stress_scale_n_per_mm2 * g.segment_depth_mm * g.middle_length_mm
    return KernelUnits(g.middle_length_mm, force, force * g.middle_length_mm)


def base_kernel(cfg: SimConfig, units: KernelUnits) -> dict:
    """The solver's slots of the medium, the hinges and the solver settings."""
    m, hg, sv = cfg.medium, cfg.hinges, cfg.solver
    return {
        "medium.cs": m.c_s,
        "medium.cf": m.c_f,
        "medium.cl": m.c_l,
        "medium.gamma": m.gamma,
        "medium.eps": m.smoothing_rel,
        "medium.mu": m.regularization,
        "hinges.k": hg.spring_n_mm_per_rad / units.torque_unit_n_mm,
        "hinges.preload": hg.preload_rad,
        "hinges.amax": math.radians(hg.open_stop_deg),
        "solver.tol": sv.tol,
        "solver.maxit": sv.max_iter,
        "solver.sfloor": sv.shape_rate_floor,
        "solver.lref": units.l_ref_mm,
        "solver.substeps": sv.substeps,
    }


def kernel_values(cfg: SimConfig) -> dict:
    """Every slot of the solver's parameter vector for `cfg`: ``NAME.SLOT`` -> a value
    or a tuple of values, the base slots first, then each effect's in registry order."""
    units = kernel_units(cfg)
    values = base_kernel(cfg, units)
    for name in EFFECTS:
        slots = effect_slots(getattr(cfg.effects, name), units)
        values.update({f"{name}.{k}": v for k, v in slots.items()})
    return values


def kernel_layout() -> dict[str, tuple[int, int]]:
    """Packed layout of the solver's parameters: slot -> (first index, length), laid
    out from the nominal configuration's slots."""
    return _layout(tuple(EFFECTS.values()))


@cache
def _layout(_effects: tuple) -> dict[str, tuple[int, int]]:
    out, start = {}, 0
    for key, value in kernel_values(SimConfig()).items():
        n = len(value) if isinstance(value, tuple) else 1
        out[key] = (start, n)
        start += n
    return out
