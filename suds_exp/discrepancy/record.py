"""Store a discrepancy run: runs, steps, candidates and localisation tables (one transaction)."""

from __future__ import annotations

import datetime as _dt
import json

import numpy as np
import pandas as pd
import sqlalchemy as sa

from suds_exp.discrepancy.tables import CANDIDATE_COLUMNS, STEP_COLUMNS, discrepancy_runs


def _num(x) -> float | None:
    if x is None:
        return None
    x = float(x)
    return x if np.isfinite(x) else None


def _config_json(cfg) -> str:
    return json.dumps(cfg.to_dict(), sort_keys=True)


def record_run(store, result, options, started_at: _dt.datetime) -> int:
    """Insert ``result`` (a `DiscrepancyResult`) and return its run id."""
    step_rows = [_step_row(s) for s in result.steps]
    cand_rows = [_candidate_row(s.index, r) for s in result.steps for r in s.candidates]
    loc_frames = [_with_step(s.localisation, s.index) for s in result.steps]
    with store.write() as conn:
        run_id = int(conn.execute(sa.text("SELECT nextval('discrepancy_runs_id_seq')")).scalar())
        conn.execute(
            discrepancy_runs.insert().values(
                id=run_id,
                name=result.name,
                prep_version=result.prep_version,
                start_model=_config_json(result.start_model),
                final_model=_config_json(result.final_model),
                options=json.dumps(options.to_dict(), default=str, sort_keys=True),
                train_trials=json.dumps(result.train_trials),
                test_trials=json.dumps(result.test_trials),
                named_effects=json.dumps([n["candidate"] for n in result.named]),
                outcome=result.outcome,
                report_dir=str(result.report_dir) if result.report_dir else None,
                seconds=float(result.seconds),
                started_at=started_at,
                finished_at=_dt.datetime.now(),
            )
        )
        steps = pd.DataFrame(step_rows, columns=[c for c in STEP_COLUMNS if c != "run_id"])
        steps.insert(0, "run_id", run_id)
        store.insert_df(conn, "discrepancy_steps", steps)
        if cand_rows:
            cands = pd.DataFrame(cand_rows, columns=[c for c in CANDIDATE_COLUMNS if c != "run_id"])
            cands.insert(0, "run_id", run_id)
            store.insert_df(conn, "discrepancy_candidates", cands)
        loc = pd.concat(loc_frames, ignore_index=True)
        loc.insert(0, "run_id", run_id)
        store.insert_df(conn, "discrepancy_localisation", loc)
        _record_discoveries(store, conn, run_id, result)
    return run_id


def _with_step(frame: pd.DataFrame, step: int) -> pd.DataFrame:
    out = frame.copy()
    out.insert(0, "step", step)
    return out


def _step_row(s) -> dict:
    a = s.accepted
    return {
        "step": s.index,
        "model": _config_json(s.model),
        "test_loss": float(s.test_loss),
        "test_rmse_vx": float(s.test_rmse[0]),
        "test_rmse_vy": float(s.test_rmse[1]),
        "test_rmse_wz": float(s.test_rmse[2]),
        "n_candidates": len(s.candidates),
        "decision": s.decision,
        "accepted": a.candidate.label if a else None,
        "parameter": a.candidate.param if a else None,
        "value": _num(a.value) if a else None,
        "ci_low": _num(a.ci[0]) if a and a.ci else None,
        "ci_high": _num(a.ci[1]) if a and a.ci else None,
        "unit": a.candidate.unit if a else None,
        "p_adjusted": _num(a.p_adjusted) if a else None,
        "gap_closed": _num(s.gap_closed),
        "systematic_z": _num(s.systematic[0]),
        "systematic_p": _num(s.systematic[1]),
        "correlations": None
        if s.correlations is None
        else json.dumps(s.correlations.head(20).values.tolist()),
    }


def _candidate_row(step: int, r) -> dict:
    return {
        "step": step,
        "candidate": r.candidate.label,
        "effect": r.candidate.effect,
        "parameter": r.candidate.param,
        "value": _num(r.value),
        "ci_low": _num(r.ci[0]) if r.ci else None,
        "ci_high": _num(r.ci[1]) if r.ci else None,
        "unit": r.candidate.unit,
        "train_loss_before": _num(r.train_before),
        "train_loss_after": _num(r.train_after),
        "test_loss_before": _num(np.mean(r.test_before)),
        "test_loss_after": _num(np.mean(r.test_after)),
        "improvement": _num(r.improvement),
        "p_value": _num(r.p_value),
        "p_adjusted": _num(r.p_adjusted),
        "significant": bool(r.significant),
        "accepted": bool(r.accepted),
        "n_replays": int(r.n_replays),
        "seconds": float(r.seconds),
    }


def _record_discoveries(store, conn, run_id: int, result) -> None:
    """Rows of discrepancy_discoveries and discrepancy_correction_terms (migration 007)."""
    runs, terms = [], []
    for s in result.steps:
        d = s.discovery
        if d is None:
            continue
        runs.append(
            {
                "run_id": run_id,
                "step": s.index,
                "significant": bool(d.significant),
                "p_value": _num(d.p_value),
                "test_loss_before": _num(np.mean(d.test_before)),
                "test_loss_after": _num(np.mean(d.test_after)),
                "gap_closed": _num(d.improvement),
                "physics": d.physics,
                "physics_body": d.physics_by_part["body"],
                "physics_passive": d.physics_by_part["passive"],
                "leading_features": json.dumps(d.leading),
                "equations": json.dumps(d.equations()),
                "n_features": len(d.features),
                "seconds": float(d.seconds),
            }
        )
        for t in d.terms:
            terms.append(
                {
                    "run_id": run_id,
                    "step": s.index,
                    "channel": t.channel,
                    "feature": t.feature.name,
                    "family": t.feature.family,
                    "unit": t.unit,
                    "coefficient": float(t.coef),
                    "ci_low": _num(t.ci[0]),
                    "ci_high": _num(t.ci[1]),
                    "weight": _num(t.weight),
                }
            )
    checks = [
        {
            "run_id": run_id,
            "step": s.index,
            "effect": c.effect,
            "significant": bool(c.significant),
            "p_value": _num(c.p_value),
            "test_loss_constant": _num(np.mean(c.test_before)),
            "test_loss_varying": _num(np.mean(c.test_after)),
            "varies_with": c.varies_with,
            "at_range_edge": bool(c.at_range_edge),
        }
        for s in result.steps
        if (c := getattr(s, "constancy", None)) is not None
    ]
    if checks:
        store.insert_df(conn, "discrepancy_constancy", pd.DataFrame(checks))
    if runs:
        store.insert_df(conn, "discrepancy_discoveries", pd.DataFrame(runs))
    if terms:
        store.insert_df(conn, "discrepancy_correction_terms", pd.DataFrame(terms))
