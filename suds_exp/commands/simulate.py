"""The work behind `suds-exp simulate`, `connection` and `effects` (the CLI only parses
options and prints), plus the parsers of their option strings that the CLI calls.
Simulating then ingesting is `suds_exp.workflows.simulate`."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from suds_exp import console
from suds_exp.errors import ConfigError
from suds_exp.robot import FREQUENCIES_HZ, GAITS, parse_frequency
from suds_exp.sim.config import SimConfig, load_config
from suds_exp.sim.connection import local_connection, save_connection
from suds_exp.sim.dataset import SimDesign, check_cycles
from suds_exp.sim.effects import apply_effects, effect_library
from suds_exp.sim.schedule import split_effects
from suds_exp.workflows.simulate import simulate_and_ingest


def parse_gaits(text: str | None) -> tuple[str, ...]:
    """``"S+,O"`` -> ("S+", "O"); None -> all five gaits."""
    if not text:
        return GAITS
    gaits = tuple(g.strip() for g in text.split(",") if g.strip())
    bad = [g for g in gaits if g not in GAITS]
    if bad or not gaits:
        raise ConfigError(
            f"gaits {text!r}: expected a comma list of {', '.join(GAITS)}", param="gaits"
        )
    return gaits


def parse_freqs(text: str | None) -> tuple[float, ...]:
    """``"1/3,0.5,1"`` -> (0.333.., 0.5, 1.0) Hz; None -> 1/3, 1/2, 1."""
    if not text:
        return FREQUENCIES_HZ
    try:
        freqs = tuple(parse_frequency(f) for f in text.split(",") if f.strip())
    except ValueError:
        raise ConfigError(
            f"frequencies_hz {text!r}: expected Hz values > 0 such as 1/3,0.5,1",
            param="frequencies_hz",
        ) from None
    if not freqs:
        raise ConfigError(
            f"frequencies_hz {text!r}: expected Hz values > 0 such as 1/3,0.5,1",
            param="frequencies_hz",
        )
    return freqs


def parse_freq(text: str) -> float:
    """``"1/2"`` -> 0.5 Hz: one frequency (a gait's); a list is refused."""
    freqs = parse_freqs(text)
    if len(freqs) != 1:
        raise ConfigError(
            f"frequency_hz {text!r}: expected one frequency in Hz, such as 1/2",
            param="frequency_hz",
        )
    return freqs[0]


def parse_cycles(text: str | None) -> tuple[int, int]:
    """``"10:30"`` -> (10, 30); ``"12"`` -> (12, 12); None -> (10, 30)."""
    if not text:
        return (10, 30)
    lo, _, hi = text.partition(":")
    try:
        lo_i = int(lo)
        hi_i = int(hi) if hi else lo_i
    except ValueError:
        raise ConfigError(
            f"cycles {text!r}: expected MIN:MAX, e.g. 10:30", param="cycles"
        ) from None
    return check_cycles((lo_i, hi_i), text)


def build_config(
    config_path: Path | None, effects: Sequence[str] = (), param: str = "effects"
) -> SimConfig:
    """Nominal config, or the file's, with `NAME=VALUE` effect settings applied in order
    (errors name ``param``, the parameter that carried them)."""
    cfg = load_config(config_path) if config_path is not None else SimConfig()
    return apply_effects(cfg, effects, param)


def simulate_command(
    out: Path,
    store=None,
    progress: bool = False,
    config: SimConfig | None = None,
    design: SimDesign | None = None,
) -> dict:
    """Simulate ``design`` (a `SimDesign`; default: the paper's) on the robot of
    ``config`` into `out` and (given a `Store`) ingest it; a JSON-ready summary.
    ``progress``: a bar over the trials."""
    run = simulate_and_ingest(store, out, config, design, progress=progress)
    ds = run.dataset
    summary = {
        "out": str(out),
        "manifest": str(ds.manifest),
        "files": [str(p) for p in ds.tsv_paths],
        "n_trials": len(ds.tsv_paths),
        "simulated_seconds": round(float(ds.simulated_seconds), 3),
        "wall_seconds": round(run.wall_seconds, 3),
        "trial_ids": [r.trial_id for r in run.ingested] if store is not None else None,
    }
    return summary


def connection_command(
    out: Path,
    grid: int = 21,
    half_range: float = 2.5,
    geometry: str = "robot",
    config: SimConfig | None = None,
    n_directions: int = 8,
    figures: bool = True,
) -> dict:
    """Compute the local connection of ``config`` (default nominal), write CSV (+ figures);
    a JSON-ready summary."""
    cfg = config or SimConfig()
    conn = local_connection(grid, half_range, geometry, cfg, n_directions=n_directions)
    written = save_connection(conn, out, figures=figures)
    return {
        "csv": str(written[0]),
        "figures": [str(p) for p in written[1:]],
        "geometry": geometry,
        "grid": grid,
        "range": half_range,
        "length_unit": "mm" if geometry == "robot" else "total swimmer length",
        "max_residual": conn.max_residual,
    }


def effects_table(config: SimConfig | None = None) -> pd.DataFrame:
    """One row per effect parameter of ``config`` (default nominal): effect, state,
    parameter, unit, nominal, value, range, meaning (with the source of the range where
    there is one)."""
    rows = []
    for e in effect_library(config or SimConfig()):
        for p in e["parameters"]:
            rows.append(
                {
                    "effect": e["name"],
                    "state": e["state"],
                    "nominal_state": e["nominal_state"],
                    "parameter": p["name"] + (" *" if p["name"] == e["main"] else ""),
                    "unit": p["unit"],
                    "nominal": p["nominal"],
                    "value": p["value"],
                    "range": f"{p['range'][0]} .. {p['range'][1]}",
                    "meaning (source)": p["description"],
                }
            )
    return pd.DataFrame(rows)


def say_if_compiling() -> None:
    """On stderr, before a first simulation after an install: the kernels compile once."""
    from suds_exp.sim.precompile import COMPILE_S, kernels_cached

    if not kernels_cached():
        console.err.print(
            f"compiling the simulator once (numba): about {COMPILE_S} s on an idle core, "
            "more on a busy one; later runs load it from the cache",
            highlight=False,
        )


def simulate_options(
    out: Path,
    config_path: Path | None = None,
    gaits: str | None = None,
    freqs: str | None = None,
    repeats: int = 4,
    cycles: str | None = None,
    seed: int = 0,
    effects: Sequence[str] = (),
    gait_file: Path | None = None,
    store=None,
    progress: bool = False,
) -> dict:
    """`suds-exp simulate` from its option strings: the paper's design (`simulate_command`)
    or, with ``gait_file``, trials of that gait (`simulate_file_command`); ingested into
    ``store`` when one is given. A JSON-ready summary."""
    if progress:
        say_if_compiling()
    if gait_file is not None:
        return _simulate_gait_file(
            out,
            config_path,
            gaits,
            freqs,
            repeats,
            cycles,
            seed,
            effects,
            gait_file,
            store,
            progress,
        )
    gait_list, freq_list, cycle_range = parse_gaits(gaits), parse_freqs(freqs), parse_cycles(cycles)
    static, changes = split_effects(list(effects))
    design = SimDesign(gait_list, freq_list, repeats, cycle_range, seed, changes)
    return simulate_command(out, store, progress, build_config(config_path, static), design)


def _simulate_gait_file(
    out, config_path, gaits, freqs, repeats, cycles, seed, effects, gait_file, store, progress
) -> dict:
    from suds_exp.commands.gait import simulate_file_command

    if gaits:
        raise ConfigError("use just one of --gaits and --gait-file", param="gaits")
    if any("@" in e for e in effects):
        raise ConfigError("--gait-file takes effects without a schedule (NAME=VALUE)")
    return simulate_file_command(
        out,
        gait_file,
        build_config(config_path, list(effects)),
        frequencies_hz=parse_freqs(freqs),
        repeats=repeats,
        cycles=parse_cycles(cycles),
        seed=seed,
        store=store,
        progress=progress,
    )


def simulate_text(summary: dict) -> str:
    """The one line `suds-exp simulate` prints for the summary of `simulate_options`."""
    ingested = f"; ingested trials {summary['trial_ids']}" if summary["trial_ids"] else ""
    if "gait" in summary:
        return (
            f"wrote {summary['n_trials']} trials of {summary['gait']} "
            f"({summary['simulated_seconds']:.0f} s of robot time) and {summary['manifest']}"
            + ingested
        )
    return (
        f"wrote {summary['n_trials']} trials ({summary['simulated_seconds']:.0f} s of robot "
        f"time in {summary['wall_seconds']:.1f} s) and {summary['manifest']}" + ingested
    )
