"""Figures: box plots by similarity category and the sample-efficiency curves.

Box plots use matplotlib's default box-plot parameters, as the paper's figures do. All
drawing goes through the Agg backend on explicit ``Figure`` objects, so no display and
no global pyplot state are involved.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import LogFormatter

from suds_exp.analysis.categories import FREQ_SIM, GAIT_SIM, at_cycles, learner_order

_FREQ_TITLE = {"different": "different frequency", "same": "same frequency"}
_GAIT_TITLE = {"far": "far gait", "near": "near gait", "same": "same gait"}
YLABEL = "ln RMS error of vx (mm/s)"
DPI = 100


def _save(fig: Figure, path: Path) -> Path:
    FigureCanvasAgg(fig)
    fig.savefig(path, dpi=DPI)
    return path


def _panel(ax, rows: pd.DataFrame, models: list[str], title: str) -> None:
    groups = rows.groupby("model")["ln_rmse_vx"]
    data = [groups.get_group(m).to_numpy() if m in groups.groups else np.array([]) for m in models]
    ax.boxplot(data)
    ax.set_xticks(range(1, len(models) + 1), models, rotation=30, ha="right")
    ax.set_title(f"{title} (n={len(rows)})", fontsize="medium")


def category_boxplots(
    results: pd.DataFrame, out_dir: Path, n_cycles: int | None = None
) -> dict[str, Path]:
    """Write the three box-plot figures of ln RMS error of vx by learner.

    ``boxplot_frequency.png``: different (left) and same (right) frequency;
    ``boxplot_gait.png``: far, near, same gait; ``boxplot_combined.png``: each frequency
    category (rows) by each gait category (columns). Uses the results at ``n_cycles``
    (default the campaign's most common training size). Returns name -> path.
    """
    rows, size = at_cycles(results, n_cycles)
    models = learner_order(rows["model"])
    width = max(4.0, 0.6 * len(models) + 1.5)
    paths = {}

    for column, cats, titles, what in (
        ("freq_sim", FREQ_SIM, _FREQ_TITLE, "frequency"),
        ("gait_sim", GAIT_SIM, _GAIT_TITLE, "gait"),
    ):
        fig = Figure(figsize=(len(cats) * width, 4.5), layout="constrained")
        axes = fig.subplots(1, len(cats), sharey=True)
        for ax, cat in zip(axes, cats, strict=True):
            _panel(ax, rows[rows[column] == cat], models, titles[cat])
        axes[0].set_ylabel(YLABEL)
        fig.suptitle(f"Prediction error by {what} similarity ({size} training cycles)")
        paths[f"boxplot_{what}"] = _save(fig, out_dir / f"boxplot_{what}.png")

    fig = Figure(figsize=(3 * width, 8.5), layout="constrained")
    axes = fig.subplots(len(FREQ_SIM), len(GAIT_SIM), sharey=True)
    for i, fcat in enumerate(FREQ_SIM):
        for j, gcat in enumerate(GAIT_SIM):
            sel = rows[(rows["freq_sim"] == fcat) & (rows["gait_sim"] == gcat)]
            _panel(axes[i, j], sel, models, f"{_FREQ_TITLE[fcat]}, {_GAIT_TITLE[gcat]}")
        axes[i, 0].set_ylabel(YLABEL)
    fig.suptitle(f"Prediction error by frequency and gait similarity ({size} training cycles)")
    paths["boxplot_combined"] = _save(fig, out_dir / "boxplot_combined.png")
    return paths


def efficiency_figure(
    iqr: pd.DataFrame, slopes: pd.DataFrame, path: Path, panel: str = "frequency_hz"
) -> Path:
    """Write the sample-efficiency figure: median RMS error of vx (line, markers) and its
    inter-quartile band against training cycles, log-log, one panel per frequency, one
    line per learner labelled with its fitted upper-range slope.

    ``iqr`` is `iqr_table` output, ``slopes`` `slope_table` output. ``panel``: the column
    of both whose values make the panels (default the frequency, titled in Hz; another
    column's values are the titles as they are).
    """
    freqs = sorted(iqr[panel].unique())
    models = learner_order(iqr["model"])
    fig = Figure(figsize=(5.0 * len(freqs), 4.8), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(freqs), sharey=True))
    slope_of = dict(
        zip(zip(slopes[panel], slopes["model"], strict=True), slopes["slope"], strict=True)
    )
    for ax, freq in zip(axes, freqs, strict=True):
        for k, model in enumerate(models):
            g = iqr[(iqr[panel] == freq) & (iqr["model"] == model)]
            if g.empty:
                continue
            s = slope_of.get((freq, model), np.nan)
            label = f"{model} (slope {s:+.2f})" if np.isfinite(s) else model
            color = f"C{k % 10}"
            ax.plot(g["n_cycles"], g["median"], "o-", color=color, label=label, markersize=4)
            ax.fill_between(g["n_cycles"], g["q1"], g["q3"], color=color, alpha=0.15, linewidth=0)
        ax.set_xscale("log")
        ax.set_yscale("log")
        for axis in (ax.xaxis, ax.yaxis):  # plain numbers (2, 5, 20), not 2 x 10^0
            axis.set_major_formatter(LogFormatter())
            axis.set_minor_formatter(LogFormatter(labelOnlyBase=False, minor_thresholds=(2, 0.4)))
        ax.set_xlabel("training cycles")
        ax.set_title(f"{frequency_name(freq)} Hz" if panel == "frequency_hz" else str(freq))
        fitted = slopes[slopes[panel] == freq]
        title = None
        if not fitted.empty:
            title = f"slope over {fitted['cycles_from'].min()}-{fitted['cycles_to'].max()} cycles"
        ax.legend(fontsize="small", title=title, title_fontsize="small")
    axes[0].set_ylabel("RMS error of vx (mm/s), median and IQR")
    fig.suptitle("RMS error against training cycles (log-log)")
    return _save(fig, path)


def frequency_name(freq: float) -> str:
    """``1/3``, ``1/2``, ``1``: a frequency in Hz as a small fraction when it is one."""
    for den in (1, 2, 3, 4, 5, 6):
        num = freq * den
        if abs(num - round(num)) < 1e-4:
            return f"{round(num)}/{den}" if den > 1 else f"{round(num)}"
    return f"{freq:g}"


def axis_boxplots(
    results: pd.DataFrame, design, out_dir: Path, n_cycles: int | None = None
) -> dict[str, Path]:
    """Write one box-plot figure per declared axis of ``design``
    (`suds_exp.experiment.ExperimentDesign`): ``boxplot_<axis>.png``, ln RMS error of vx
    by learner, one panel per pair category along the axis (same / near / far, same /
    lower / higher, same / different). ``results`` must carry the ``<axis>_pair`` columns
    (`suds_exp.analysis.design_tables.label_pairs`). Returns name -> path."""
    rows, size = at_cycles(results, n_cycles)
    models = learner_order(rows["model"])
    width = max(4.0, 0.6 * len(models) + 1.5)
    paths = {}
    for axis in design.axes:
        cats = axis.categories
        fig = Figure(figsize=(len(cats) * width, 4.5), layout="constrained")
        axes = np.atleast_1d(fig.subplots(1, len(cats), sharey=True))
        for ax, cat in zip(axes, cats, strict=True):
            _panel(ax, rows[rows[f"{axis.name}_pair"] == cat], models, f"{cat} {axis.name}")
        axes[0].set_ylabel(YLABEL)
        fig.suptitle(f"Prediction error by {axis.name} ({axis.kind}; {size} training cycles)")
        paths[f"boxplot_{axis.name}"] = _save(fig, out_dir / f"boxplot_{axis.name}.png")
    return paths
