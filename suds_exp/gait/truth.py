"""What the simulator does with a gait: the ground truth of prediction and design.

The gait is followed exactly (no actuator lag or noise, the mean bed), started at phase 0
from the origin with flippers closed; the net motion per cycle is measured on the
simulator's own world poses over cycles 3-5 (0-based 2, 3, 4), after the flippers and the
body have settled into the cycle.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from suds_exp.gait.motion import CycleMotion, cycle_motion
from suds_exp.gait.shape import TWO_PI, Gait
from suds_exp.sim import SimConfig, simulate_prescribed

#: Cycles simulated and the cycles (0-based) measured.
N_CYCLES = 6
MEASURED = (2, 3, 4)
RATE_HZ = 100.0


def simulate_gaits(
    gaits: Sequence[Gait], frequency_hz: float = 0.5, config: SimConfig | None = None
) -> list[CycleMotion]:
    """Net motion per cycle of each gait on the simulator, in one batched physics call.

    frequency_hz: Hz; config: simulator (default nominal). Returns one `CycleMotion`
    (forward_mm, lateral_mm, turn_rad, mean_vx_mm_s) per gait, mean of cycles 3-5.
    """
    if not gaits:
        return []
    per = int(round(RATE_HZ / frequency_hz))
    n = N_CYCLES * per + 1
    theta = TWO_PI * np.arange(n) / per
    phi = np.stack([g.shape(theta) for g in gaits])
    out = simulate_prescribed(phi, 1 / RATE_HZ, config or SimConfig())
    return [
        cycle_motion(out["pose"][k], per, MEASURED, out["vel"][k, :, 0]) for k in range(len(gaits))
    ]


def simulate_forward(gaits: Sequence[Gait], frequency_hz: float = 0.5, config=None) -> np.ndarray:
    """Forward displacement per cycle (mm) of each gait on the simulator: array (n,)."""
    return np.array([m.forward_mm for m in simulate_gaits(gaits, frequency_hz, config)])
