"""The report page of a discrepancy run: index.html, PNG figures, Markdown and CSV tables.

Self-contained (no network resources): figures are PNG files beside index.html.
"""

from __future__ import annotations

import html
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

CHANNEL_UNITS = {"vx": "mm/s", "vy": "mm/s", "wz": "rad/s"}


def _steps_table(result) -> pd.DataFrame:
    rows = []
    for s in result.steps:
        a = s.accepted
        rows.append(
            {
                "step": s.index,
                "held_out_loss": s.test_loss,
                "rmse_vx_mm_s": s.test_rmse[0],
                "rmse_vy_mm_s": s.test_rmse[1],
                "rmse_wz_rad_s": s.test_rmse[2],
                "decision": s.decision,
                "named": a.candidate.label if a else "",
                "parameter": a.candidate.param if a and a.candidate.param else "",
                "value": a.value if a else np.nan,
                "ci_low": a.ci[0] if a and a.ci else np.nan,
                "ci_high": a.ci[1] if a and a.ci else np.nan,
                "unit": a.candidate.unit if a else "",
                "p_adjusted": a.p_adjusted if a else np.nan,
                "gap_closed": s.gap_closed if s.gap_closed is not None else np.nan,
                "systematic_p": s.systematic[1],
                # the named effect's check (partial.py): is its strength constant?
                "varying_strength_p": s.constancy.p_value if s.constancy else np.nan,
                "varies_with": s.constancy.varies_with if s.constancy else "",
            }
        )
    return pd.DataFrame(rows)


def _candidates_table(result) -> pd.DataFrame:
    rows = []
    for s in result.steps:
        for r in s.candidates:
            rows.append(
                {
                    "step": s.index,
                    "candidate": r.candidate.label,
                    "parameter": r.candidate.param or "",
                    "value": r.value if r.value is not None else np.nan,
                    "ci_low": r.ci[0] if r.ci else np.nan,
                    "ci_high": r.ci[1] if r.ci else np.nan,
                    "unit": r.candidate.unit,
                    "improvement": r.improvement,
                    "p_adjusted": r.p_adjusted,
                    "significant": r.significant,
                    "accepted": r.accepted,
                    "seconds": r.seconds,
                }
            )
    return pd.DataFrame(rows)


def _md(df: pd.DataFrame) -> str:
    cols = list(df.columns)
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for row in df.itertuples(index=False):
        cells = [f"{v:.4g}" if isinstance(v, float) else str(v) for v in row]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _fig_condition(result, path: Path) -> None:
    first, last = result.steps[0].localisation, result.steps[-1].localisation
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    for ax, ch in zip(axes, CHANNEL_UNITS, strict=True):
        for loc, label, off in ((first, "before", -0.2), (last, "after", 0.2)):
            d = loc[(loc.view == "condition") & (loc.channel == ch)]
            names = [f"{g} {f:.2g}Hz" for g, f in zip(d.gait, d.frequency_hz, strict=True)]
            x = np.arange(len(d))
            ax.bar(x + off, d.rms, width=0.4, label=label)
            ax.set_xticks(x, names, rotation=60, fontsize=7)
        ax.set_ylabel(f"RMS residual {ch} ({CHANNEL_UNITS[ch]})")
    axes[0].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _fig_view(result, view: str, path: Path, xlabel: str) -> None:
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.4))
    for ax, ch in zip(axes, CHANNEL_UNITS, strict=True):
        for s in (result.steps[0], result.steps[-1]):
            d = s.localisation
            d = d[(d.view == view) & (d.channel == ch)].sort_values("x")
            label = f"step {s.index}"
            ax.plot(d.x, d.rms, marker="o", label=label)
            ax.fill_between(d.x, d.band_lo, d.band_hi, alpha=0.25)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(f"RMS residual {ch} ({CHANNEL_UNITS[ch]})")
    axes[0].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _fig_shape(result, path: Path) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
    for ax, s in zip(axes, (result.steps[0], result.steps[-1]), strict=True):
        d = s.localisation
        d = d[(d.view == "shape") & (d.channel == "vx")]
        sc = ax.scatter(d.x, d.y, c=d.rms, s=160, marker="s", cmap="viridis")
        fig.colorbar(sc, ax=ax, label="RMS residual vx (mm/s)")
        ax.set_xlabel("phi1 (rad)")
        ax.set_ylabel("phi2 (rad)")
        ax.set_title(f"step {s.index}")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _fig_example(result, path: Path) -> None:
    first, last = result.steps[0].example, result.steps[-1].example
    fig, axes = plt.subplots(3, 1, figsize=(9, 7), sharex=True)
    t = first["t"] - np.nanmin(first["t"])
    for c, (ax, ch) in enumerate(zip(axes, CHANNEL_UNITS, strict=True)):
        ax.plot(t, first["measured"][:, c], "k", label="measured")
        ax.plot(t, first["simulated"][:, c], label="model, step 0")
        ax.plot(t, last["simulated"][:, c], "--", label=f"model, step {result.steps[-1].index}")
        ax.set_ylabel(f"{ch} ({CHANNEL_UNITS[ch]})")
    axes[0].set_title(f"held-out trial {first['trial_id']}")
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("time in window (s)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _fig_candidates(result, path: Path) -> None:
    steps = [s for s in result.steps if s.candidates]
    if not steps:
        return
    fig, axes = plt.subplots(1, len(steps), figsize=(4.5 * len(steps), 3.4), squeeze=False)
    for ax, s in zip(axes[0], steps, strict=True):
        labels = [r.candidate.label for r in s.candidates]
        imp = [r.improvement for r in s.candidates]
        colors = [
            "tab:green" if r.accepted else "tab:blue" if r.significant else "tab:gray"
            for r in s.candidates
        ]
        ax.barh(labels, imp, color=colors)
        ax.set_xlabel("held-out loss removed (fraction)")
        ax.set_title(f"step {s.index} candidates")
        ax.set_xlim(min(-0.1, min(imp)), 1)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _discovery_table(d) -> pd.DataFrame:
    return pd.DataFrame(
        [
            {
                "channel": t.channel,
                "feature": t.feature.name,
                "family": t.feature.family,
                "coefficient": t.coef,
                "ci_low": t.ci[0],
                "ci_high": t.ci[1],
                "unit": t.unit,
                "share": t.weight,
            }
            for t in d.terms
        ],
        columns=[
            "channel",
            "feature",
            "family",
            "coefficient",
            "ci_low",
            "ci_high",
            "unit",
            "share",
        ],
    )


def _fig_discovery(d, path: Path) -> None:
    fig, ax = plt.subplots(figsize=(9, 3.4))
    x = np.arange(len(d.test_trials))
    ax.bar(x - 0.2, d.test_before, width=0.4, label="model")
    ax.bar(x + 0.2, d.test_after, width=0.4, label="model + learned correction")
    ax.set_xticks(x, [str(int(t)) for t in d.test_trials], rotation=60, fontsize=7)
    ax.set_xlabel("held-out trial")
    ax.set_ylabel("loss (normalised)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _discovery_parts(result, out: Path) -> list[str]:
    """The learned-correction section (empty when no correction was tried)."""
    d = result.steps[-1].discovery
    if d is None:
        return []
    table = _discovery_table(d)
    table.to_csv(out / "correction.csv", index=False)
    (out / "correction.md").write_text(_md(table) if not table.empty else "(no term)\n")
    _fig_discovery(d, out / "discovery.png")
    verdict = "added to the model" if d.significant else "not added (held-out test failed)"
    return _shares(result) + [
        "<h2>Learned correction (no named effect explains the gap)</h2>",
        f"<p>{html.escape(verdict)}: held-out loss {np.mean(d.test_before):.4g} -> "
        f"{np.mean(d.test_after):.4g} ({d.improvement:.0%} closed, p = {d.p_value:.2g}); "
        f"resembles <b>{html.escape(d.physics or 'nothing')}</b> "
        f"({html.escape(_by_part(d))}); leading features "
        f"{html.escape(', '.join(d.leading[:3]))}.</p>",
        "<pre>" + html.escape("\n".join(d.equations()) or "(no term)") + "</pre>",
        table.to_html(index=False, float_format=lambda v: f"{v:.4g}") if not table.empty else "",
        "<h3>Held-out loss per trial, with and without the correction</h3>"
        "<img src='discovery.png' width='100%'>",
    ]


def _by_part(d) -> str:
    """'body velocity: X; passive shape: Y', each part only where it has a term."""
    names = {"body": "body velocity", "passive": "passive shape"}
    parts = [f"{names[k]}: {v}" for k, v in d.physics_by_part.items() if v]
    return "; ".join(parts) or "no term"


def _why_partial(step) -> str:
    c, a = step.constancy, step.accepted
    why = []
    if c.significant:
        why.append(f"its strength varies with {c.varies_with}, p = {c.p_value:.2g}")
    if c.at_range_edge:
        why.append(f"its fit, {a.value:.4g} {a.candidate.unit}, is at the edge of its range")
    return "; ".join(why)


def _shares(result) -> list[str]:
    """How much of the held-out gap each part closed: the effects named as partial
    explanations, then the learned correction (the form-mismatch case)."""
    partial = [s for s in result.steps if s.decision == "partial"]
    if not partial:
        return []
    d = result.steps[-1].discovery
    g0 = result.gap_before
    parts = [
        f"{s.accepted.candidate.label} ({_why_partial(s)}: a partial explanation, not the "
        f"cause) closed {s.gap_closed:.0%} of the gap it was given"
        for s in partial
    ]
    rest = (
        f"the learned correction closed {d.improvement:.0%} of what remained"
        if d is not None and d.significant
        else "what remained is unexplained"
    )
    total = 1 - result.gap_after_correction / g0 if g0 > 0 else 0.0
    return [f"<p>{html.escape('; '.join(parts) + '; ' + rest)}; together {total:.0%}.</p>"]


def write_report(result, out: Path) -> Path:
    """Write the report of ``result`` (a `DiscrepancyResult`) into ``out``; return ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    steps, cands = _steps_table(result), _candidates_table(result)
    loc = pd.concat([s.localisation.assign(step=s.index) for s in result.steps], ignore_index=True)
    steps.to_csv(out / "steps.csv", index=False)
    cands.to_csv(out / "candidates.csv", index=False)
    loc.to_csv(out / "localisation.csv", index=False)
    (out / "steps.md").write_text(_md(steps))
    (out / "candidates.md").write_text(_md(cands) if not cands.empty else "(no candidates)\n")
    figures = [
        (
            "condition.png",
            "Residual RMS by condition, held-out and training trials, before and after",
            lambda p: _fig_condition(result, p),
        ),
        (
            "phase.png",
            "Residual RMS by phase (band: 95% trial bootstrap)",
            lambda p: _fig_view(result, "phase", p, "phase (rad)"),
        ),
        (
            "time.png",
            "Residual RMS over trial time (0 = start, 1 = end)",
            lambda p: _fig_view(result, "time", p, "position in trial"),
        ),
        ("shape.png", "Residual RMS of vx over shape space", lambda p: _fig_shape(result, p)),
        (
            "candidates.png",
            "Held-out improvement of each candidate (green: named)",
            lambda p: _fig_candidates(result, p),
        ),
        (
            "example.png",
            "One held-out trial: measured vs simulated body velocity",
            lambda p: _fig_example(result, p),
        ),
    ]
    parts = [
        "<!doctype html><html><head><meta charset='utf-8'>",
        f"<title>{html.escape(result.name)}</title>",
        "<style>body{font-family:sans-serif;max-width:1100px;margin:auto}"
        "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px}</style>",
        "</head><body>",
        f"<h1>Discrepancy run {html.escape(result.name)}</h1>",
        f"<p><b>{html.escape(result.outcome)}</b></p>",
        f"<p>Held-out loss (mean normalised squared residual) {result.gap_before:.4g} before, "
        f"{result.gap_after:.4g} after; {len(result.train_trials)} training and "
        f"{len(result.test_trials)} held-out trials; {result.seconds:.0f} s.</p>",
        "<h2>Steps</h2>",
        steps.to_html(index=False, float_format=lambda v: f"{v:.4g}"),
        "<h2>Candidates</h2>",
        cands.to_html(index=False, float_format=lambda v: f"{v:.4g}") if not cands.empty else "",
    ]
    last = result.steps[-1]
    if last.correlations is not None:
        parts += [
            "<h2>Unexplained gap: correlation of the residual with measured signals</h2>",
            last.correlations.head(15).to_html(index=False, float_format=lambda v: f"{v:.3f}"),
        ]
        last.correlations.to_csv(out / "correlations.csv", index=False)
    parts += _discovery_parts(result, out)
    for fname, caption, draw in figures:
        draw(out / fname)
        if (out / fname).exists():
            parts.append(f"<h3>{html.escape(caption)}</h3><img src='{fname}' width='100%'>")
    parts.append(
        "<p>Tables: <a href='steps.csv'>steps.csv</a>, <a href='candidates.csv'>candidates.csv"
        "</a>, <a href='localisation.csv'>localisation.csv</a></p></body></html>"
    )
    (out / "index.html").write_text("\n".join(parts))
    return out
