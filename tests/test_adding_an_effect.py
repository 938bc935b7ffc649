"""Adding a simulator effect takes two places: its declaration and its physics.

The worked example of docs/architecture.md ("Where a newcomer adds ..."): a toy effect is
declared here (place 1: a dataclass of its parameters, registered with
`suds_exp.sim.effect_params.effect`, whose ``slot=`` gives the compiled solver its
slot) and removed after the test. The config files, `suds-exp effects`, the
validation of its range, the discrepancy candidates and the solver's packed parameters
then know it. Place 2, its physics, reads ``prm[P_TOY]`` where it acts in `sim/rft.py`
(or acts in `sim/markers.py` on the measured markers); the toy has none, so simulating
with it must give exactly what simulating without it gives.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
import pytest
from typer.testing import CliRunner

from cli import app
from suds_exp.discrepancy.effects import candidates_for
from suds_exp.errors import ConfigError
from suds_exp.sim import (
    SimConfig,
    config_from_dict,
    effect_library,
    load_config,
    set_effect,
    simulate_prescribed,
)
from suds_exp.sim.effect_params import (
    EFFECTS,
    effect,
    main_param,
    unregister_effect,
)
from suds_exp.sim.kernel_params import kernel_layout
from suds_exp.sim.mechanics import pack_params


@dataclass
class ToyEffect:
    """Place 1: sticky beans multiply the drag by `factor` (the solver's slot ``toy.factor``)."""

    factor: float = main_param(1.0, "-", 0.5, 2.0, "drag multiplier", on=1.5, slot="factor")


@pytest.fixture
def toy():
    builtin = dict(kernel_layout()), pack_params(SimConfig())
    effect("toy")(ToyEffect)
    yield builtin
    unregister_effect("toy")


def test_a_declared_effect_is_configured_listed_checked_and_packed(toy, tmp_path):
    cfg = set_effect(SimConfig(), "toy=on")
    assert cfg.effects.toy.factor == 1.5
    entry = next(e for e in effect_library(cfg) if e["name"] == "toy")
    assert (entry["main"], entry["state"], entry["nominal_state"]) == ("factor", "on", "off")
    assert entry["parameters"][0]["config_key"] == "effects.toy.factor"

    path = tmp_path / "sim.toml"
    path.write_text("[effects.toy]\nfactor = 1.25\n")
    assert load_config(path).effects.toy.factor == 1.25
    path.write_text("[effects.toy]\nfactor = 3.0\n")
    with pytest.raises(ConfigError, match=r"effects\.toy\.factor: 3\.0 is outside its range"):
        load_config(path)

    layout = kernel_layout()
    # the new slot follows the built-in ones, which keep the indices compiled into rft
    builtin_layout, builtin_params = toy
    assert {k: v for k, v in layout.items() if k != "toy.factor"} == builtin_layout
    assert layout["toy.factor"] == (len(builtin_params), 1)
    np.testing.assert_array_equal(pack_params(cfg), [*builtin_params, 1.5])

    [candidate] = [c for c in candidates_for(SimConfig()) if c.effect == "toy"]
    assert candidate.label.startswith("toy")

    res = CliRunner().invoke(app, ["effects", "--json", "--effect", "toy=1.2"])
    assert res.exit_code == 0, res.output
    [listed] = [e for e in json.loads(res.output) if e["name"] == "toy"]
    assert listed["parameters"][0]["value"] == 1.2


def test_an_effect_without_physics_leaves_the_simulation_unchanged(toy):
    t = np.arange(60) * 0.01
    phi = np.stack([0.8 * np.sin(2 * np.pi * t), 0.8 * np.cos(2 * np.pi * t)], axis=1)
    with_toy = simulate_prescribed(phi, 0.01, set_effect(SimConfig(), "toy=on"))
    unregister_effect("toy")
    without = simulate_prescribed(phi, 0.01, SimConfig())
    effect("toy")(ToyEffect)
    for key in ("pose", "vel", "flippers", "residual"):
        np.testing.assert_array_equal(with_toy[key], without[key])


def test_a_removed_effect_is_forgotten():
    effect("toy")(ToyEffect)
    unregister_effect("toy")
    assert "toy" not in [e["name"] for e in effect_library()]
    assert "toy.factor" not in kernel_layout()
    with pytest.raises(ConfigError, match="effect 'toy'"):
        set_effect(SimConfig(), "toy=on")
    with pytest.raises(ConfigError, match="unknown setting 'toy'"):
        config_from_dict({"effects": {"toy": {"factor": 1.5}}})


def test_an_effect_declares_its_slots_one_way():
    @dataclass
    class Twice:
        factor: float = main_param(1.0, "-", 0.5, 2.0, "drag multiplier", on=1.5, slot="f")

        def kernel(self, units) -> dict:
            return {"f": self.factor}

    with pytest.raises(ConfigError, match="slot= or kernel"):
        effect("twice")(Twice)
    assert "twice" not in EFFECTS
