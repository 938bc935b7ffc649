"""The work behind `suds-exp gait predict | design | connection` and `simulate
--gait-file` (the CLI only parses options and prints): each returns a JSON-ready dict."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from suds_exp.errors import ConfigError
from suds_exp.gait.connection import compare_connections, learned_connection
from suds_exp.gait.design import Design, DesignOptions, design_gait
from suds_exp.gait.joints import describe, is_swimmer, match_joints, version_joints
from suds_exp.gait.plots import draw_connection, draw_design
from suds_exp.gait.predict import decimate, fit_map, predict_gait
from suds_exp.gait.shape import JOINT_LIMIT_RAD, SWIMMER_JOINTS, read_gait_file
from suds_exp.gait.trials import simulate_gait_file
from suds_exp.models import make_model
from suds_exp.models.registry import GMR
from suds_exp.preprocess import get_version
from suds_exp.sim import SimConfig, local_connection


def predict_command(
    store,
    gait_file: Path,
    frequency_hz: float,
    prep=None,
    learner: str = GMR,
    trials: Sequence[int] | None = None,
    n_boot: int = 10,
    bound: float = JOINT_LIMIT_RAD,
) -> dict:
    """`gait predict`: the gait file's predicted net motion per cycle (keys of
    `GaitPrediction.to_dict`). The file and the learner are checked before any fit."""
    gait = read_gait_file(gait_file, bound)
    make_model(learner)
    if n_boot < 0:
        raise ConfigError(f"n_boot {n_boot}: must be >= 0", param="n_boot")
    return predict_gait(store, prep, learner, gait, frequency_hz, trials, n_boot).to_dict()


#: Default folder of `gait design`'s report and verify trials, like every command's.
DESIGN_OUT = Path("reports") / "gait-design"
#: Default CSV of `gait connection` (its figure beside it).
CONNECTION_OUT = Path("reports") / "gait-connection" / "learned.csv"


def design_command(
    store,
    prep=None,
    options: DesignOptions | None = None,
    out: Path = DESIGN_OUT,
    config: SimConfig | None = None,
    progress=None,
) -> dict:
    """`gait design`: run the design loop (stored), write its report page (Markdown and
    a PNG under ``out``/design-ID/) and each designed gait's TOML beside it (``gaits``),
    and return the design as a dict."""
    design = design_gait(store, prep, options, out, config, progress)
    doc = design.to_dict()
    folder = Path(out) / f"design-{design.id}"
    folder.mkdir(parents=True, exist_ok=True)
    doc["gaits"] = []
    for it in design.iterations:
        path = folder / it.gait.name
        path.write_text(it.gait.to_toml())
        doc["gaits"].append(str(path))
    doc["report"] = str(write_design_report(store, design, Path(out)))
    return doc


def write_design_report(store, design: Design, out: Path) -> Path:
    """``out``/design-ID/report.md and design.png: the gaits on the learned height
    function (learner refitted on the version's samples as they are now; a body of two
    actuated joints only), displacement per iteration, predicted against achieved, and a
    table of the iterations."""
    folder = out / f"design-{design.id}"
    samples = get_version(store, design.prep_version).samples()
    joints = design.joints
    conn = None
    if len(joints) == 2:
        fitted = fit_map(samples, design.options.learner)
        conn = learned_connection(
            fitted.model, decimate(samples), 21, 2.0, k=fitted.k, rp0=fitted.rp0
        )
    png = draw_design(design, conn, folder / "design.png")
    lines = [
        f"# Gait design {design.id}",
        "",
        f"Version {design.prep_version}, learner {design.options.learner}, joints "
        f"{', '.join(joints)}, bound {design.options.bound:g} rad, "
        f"{design.options.frequency_hz:g} Hz, Fourier order {design.options.order}, "
        f"verify {design.options.verify}.",
        "",
        f"![design]({png.name})",
        "",
    ]
    if conn is None:
        lines += [
            f"No height function: it is drawn over two actuated joints; this body has "
            f"{len(joints)}.",
            "",
        ]
    lines += [
        "| iteration | predicted (mm/cycle) | achieved (mm/cycle) | trust radius | "
        "distance from data | inside support | trial |",
        "|---|---|---|---|---|---|---|",
    ]
    for it in design.iterations:
        ach = f"{it.achieved.forward_mm:.1f}" if it.achieved else "-"
        inside = "yes" if it.support.get("inside") else "no"
        lines.append(
            f"| {it.iteration} | {it.predicted.forward_mm:.1f} | {ach} | {it.trust_radius:.3f} | "
            f"{it.support_distance:.3f} | {inside} | {it.trial_id or '-'} |"
        )
    path = folder / "report.md"
    path.write_text("\n".join(lines) + "\n")
    return path


def connection_command(
    store,
    out: Path = CONNECTION_OUT,
    prep=None,
    learner: str = GMR,
    grid: int = 21,
    half_range: float = 2.0,
    compare: bool = False,
    config: SimConfig | None = None,
    gait_files: Sequence[Path] = (),
    directions: str = "visited",
) -> dict:
    """`gait connection`: the learned connection of version ``prep`` on a grid (CSV at
    ``out``, figure beside it as .png), with ``compare`` the simulator's own connection
    (flippers locked, ``config``) on the same grid and their normalised difference.

    directions: "visited" fits each shape's connection from the shape velocities the data
    took near each shape (the learner is only trusted there); "uniform" from 16 evenly
    spaced ones (see `learned_connection`).

    The connection is a field over two joints' shapes: a version of another number of
    actuated joints is refused in one line, as is ``compare`` on a body the simulator
    does not move (not the swimmer)."""
    make_model(learner)
    gaits = [read_gait_file(p) for p in gait_files]
    if grid < 3:
        raise ConfigError(f"grid {grid}: need at least 3 points per axis", param="grid")
    version = get_version(store, prep)
    joints = version_joints(version.params)
    where = describe(version.name, version.params)
    if len(joints) == 1:
        raise ConfigError(
            f"gait connection: {where}: the connection is drawn over two actuated joints; "
            "with one, a gait goes back and forth over the same shapes and its curl is "
            "empty (use gait predict or gait design)"
        )
    if len(joints) > 2:
        raise ConfigError(
            f"gait connection: {where}: the connection is drawn over two actuated joints; "
            f"a grid over {len(joints)} is not drawn (use gait predict or gait design)"
        )
    if compare and not is_swimmer(version.params):
        raise ConfigError(
            f"compare: {where}: the simulator's connection is the swimmer's; compare only "
            "a swimmer's version",
            param="compare",
        )
    gaits = [match_joints(g, joints, g.name) for g in gaits]
    samples = version.samples()
    fitted = fit_map(samples, learner)
    conn = learned_connection(
        fitted.model,
        decimate(samples),
        grid,
        half_range,
        k=fitted.k,
        rp0=fitted.rp0,
        directions=directions,
    )
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    conn.to_frame().to_csv(out, index=False, float_format="%.8g")
    reference = None
    summary: dict = {
        "csv": str(out),
        "learner": learner,
        "joints": list(joints),
        "directions": directions,
        "n_inside": int(conn.inside.sum()),
    }
    if compare:
        reference = local_connection(grid, half_range, "robot", config or SimConfig()).A
        summary["normalised_rms"] = compare_connections(conn, reference)
    summary["figure"] = str(draw_connection(conn, out.with_suffix(".png"), reference, gaits))
    return summary


def simulate_file_command(out: Path, gait_file: Path, config=None, **kwargs) -> dict:
    """`simulate --gait-file`: trials of the gait file (see `simulate_gait_file`); the
    simulator moves the swimmer, so the file's columns must be its joints phi1, phi2."""
    gait = match_joints(read_gait_file(gait_file), SWIMMER_JOINTS, f"{gait_file}: simulator")
    return simulate_gait_file(out, gait, config, **kwargs)


def predict_text(doc: dict, learner: str) -> str:
    """What `gait predict` prints for `predict_command`'s document: the prediction's line
    (each number with its interval when bootstrapped), then a line for a gait outside the
    data's support and one for each estimate outside its interval."""
    iv = doc["interval"]

    def num(key: str, unit: str, digits: int) -> str:
        text = f"{doc[key]:.{digits}f}"
        if key in iv:
            text += f" [{iv[key][0]:.{digits}f}, {iv[key][1]:.{digits}f}]"
        return f"{text} {unit}"

    lines = [
        f"{doc['gait']} at {doc['frequency_hz']:g} Hz ({learner}): forward "
        f"{num('forward_mm', 'mm/cycle', 1)}, lateral {num('lateral_mm', 'mm', 1)}, turn "
        f"{num('turn_rad', 'rad', 3)}, mean vx {num('mean_vx_mm_s', 'mm/s', 1)}"
        + (f" (95 % intervals over {doc['n_boot']} refits)" if iv else "")
    ]
    support = doc.get("support") or {}
    if support and not support["inside"]:
        lines.append(
            f"warning: the gait is outside the data's support (distance "
            f"{support['distance_rad']:.3f} rad > {support['radius_rad']:g} rad in shape and "
            "direction of shape velocity): the learned map extrapolates"
        )
    for key, note in doc.get("interval_notes", {}).items():
        lines.append(f"note: {key}: {note}")
    return "\n".join(lines)


def iteration_text(it) -> str:
    """The line `gait design` prints for each iteration as it is stored, flagging a gait
    outside the data's support (the trust radius may let the search go beyond it)."""
    ach = f", achieved {it.achieved.forward_mm:.1f}" if it.achieved else ""
    outside = ""
    if not it.support.get("inside", True):
        outside = (
            f"; outside the data's support (distance {it.support_distance:.3f} rad > "
            f"{it.support['radius_rad']:g} rad): the prediction extrapolates"
        )
    return (
        f"iteration {it.iteration}: predicted {it.predicted.forward_mm:.1f} mm/cycle"
        f"{ach}; trust radius {it.trust_radius:.3f} ({it.seconds:.0f} s){outside}"
    )


def connection_lines(summary: dict) -> list[str]:
    """The lines `gait connection` prints for `connection_command`'s summary."""
    lines = [f"wrote {summary['csv']} and {summary['figure']}"]
    if "normalised_rms" in summary:
        n = summary["normalised_rms"]
        lines.append(
            f"normalised RMS difference from the simulator inside the support: vx {n['vx']:.2f}, "
            f"vy {n['vy']:.2f}, wz {n['wz']:.2f}, mean {n['mean']:.2f} ({n['n_inside']} shapes)"
        )
    return lines
