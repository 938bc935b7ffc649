"""Physics simulator of the 4-flipper, 3-segment granular swimmer.

Public face:
- `SimConfig`, `load_config`, `config_from_dict`: every number of the simulator.
- `simulate_prescribed(phi, dt, config, pose0, flippers0, n_frames)`: batched physics
  driven by prescribed joint angles (measured or commanded-through-actuator).
- `simulate_dataset(out_dir, ...)`: gait x frequency x repeat design -> QTM TSV files,
  truth Parquet files and a manifest; `SimDesign`, such a design as one value.
- `effect_library()`, `set_effect(cfg, effect, {param: value})` (or
  `set_effect(cfg, "NAME=VALUE")`), `parse_effect("NAME=VALUE")`, `with_effects(cfg, {...})`.
- `local_connection(...)`, `save_connection(...)`, `compare_with_hatton(...)`.
"""

from suds_exp.sim.config import SimConfig, config_from_dict, load_config
from suds_exp.sim.connection import (
    CONNECTION_COLUMNS,
    compare_with_hatton,
    local_connection,
    save_connection,
)
from suds_exp.sim.dataset import (
    SimDesign,
    SimulatedDataset,
    plan_trials,
    simulate_dataset,
    simulate_trials,
    truth_markers,
)
from suds_exp.sim.effects import (
    EFFECT_NAMES,
    apply_effects,
    effect_library,
    parse_effect,
    set_effect,
    with_effects,
)
from suds_exp.sim.files import TRUTH_COLUMNS
from suds_exp.sim.gaits import FREQUENCIES_HZ, GAITS, actuate, gait_shape
from suds_exp.sim.markers import MARKER_NAMES, marker_layout
from suds_exp.sim.mechanics import residual_units, simulate_prescribed

__all__ = [
    "CONNECTION_COLUMNS",
    "EFFECT_NAMES",
    "FREQUENCIES_HZ",
    "GAITS",
    "MARKER_NAMES",
    "TRUTH_COLUMNS",
    "SimConfig",
    "SimDesign",
    "SimulatedDataset",
    "actuate",
    "apply_effects",
    "compare_with_hatton",
    "config_from_dict",
    "effect_library",
    "gait_shape",
    "load_config",
    "local_connection",
    "marker_layout",
    "plan_trials",
    "residual_units",
    "save_connection",
    "parse_effect",
    "set_effect",
    "simulate_dataset",
    "simulate_prescribed",
    "simulate_trials",
    "truth_markers",
    "with_effects",
]
