"""The discrepancy workflow: replay, localise, try candidates, name one, add it, repeat.

`run_discrepancy` is the library face of `suds-exp discrepancy`. Trials are split once,
by trial and stratified by condition, into a training half (candidate fits) and a
held-out half (scores and tests); every number about "the gap" is held-out.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import time
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from suds_exp.discrepancy.effects import Candidate, candidates_for
from suds_exp.discrepancy.fit_candidates import (
    CandidateResult,
    fit_candidate,
    refine_candidate,
    score_candidates,
    trial_losses,
)
from suds_exp.discrepancy.localise import localise, residual_correlations, systematic_gap
from suds_exp.discrepancy.naming import check_free, default_name, free_name
from suds_exp.discrepancy.options import DiscrepancyOptions, check_options
from suds_exp.discrepancy.partial import check_named, discover_step
from suds_exp.discrepancy.replay import (
    ReplaySettings,
    WindowSet,
    make_windows,
    measured,
    replay,
    settings_from_prep,
    window_field,
)
from suds_exp.discrepancy.result import DiscrepancyResult, Step
from suds_exp.errors import DiscrepancyError
from suds_exp.preprocess.rates import Differentiator
from suds_exp.preprocess.version import get_version
from suds_exp.progress import progress_lines
from suds_exp.sim.config import SimConfig
from suds_exp.store.files import check_writable


def split_trials(info: pd.DataFrame, rng: np.random.Generator) -> tuple[list[int], list[int]]:
    """Split trials in two halves, stratified by (gait, frequency); by trial, never sample.

    Within a condition the trials are shuffled and dealt alternately, the first to the
    training half; conditions are visited in a shuffled order so odd counts balance.
    """
    per = info.drop_duplicates("trial_id")
    train, test = [], []
    groups = list(per.groupby(["gait", "frequency_hz"], sort=True))
    for i in rng.permutation(len(groups)):
        ids = rng.permutation(groups[i][1]["trial_id"].to_numpy())
        first, second = (train, test) if len(train) <= len(test) else (test, train)
        first.extend(int(x) for x in ids[0::2])
        second.extend(int(x) for x in ids[1::2])
    return sorted(train), sorted(test)


def _observable(cand: Candidate, model: SimConfig, probe: WindowSet) -> bool:
    """Does the candidate change the replayed body velocity at all (one window)?"""
    if cand.param is None:
        configs = [model, cand.apply(model, None)]
    else:
        configs = [model, cand.apply(model, cand.bounds[0]), cand.apply(model, cand.bounds[1])]
    v = replay(probe, configs)
    ref = np.nan_to_num(v[0])
    return any(np.nanmax(np.abs(np.nan_to_num(x) - ref)) > 1e-9 for x in v[1:])


def load_pca(store, version_id: int):
    """The `PassivePCA` of a preprocessing version (None if it has none)."""
    return get_version(store, version_id).pca


def _full_rate(rs: ReplaySettings) -> ReplaySettings:
    """Settings of the undecimated replay: every captured frame, a longer warm-up."""
    return dataclasses.replace(
        rs, samples_per_cycle=10**6, warmup_cycles=max(1.5, rs.warmup_cycles)
    )


def _scales(meas: np.ndarray) -> np.ndarray:
    """Per-channel divisors of the residual: each channel's measured RMS, and, when the
    passive shape is compared (more than 3 channels), weighted so body velocity and
    passive shape count half each."""
    rms = np.sqrt(np.nanmean(meas**2, axis=(0, 1)))
    n = meas.shape[-1]
    if n == 3:
        return rms
    weights = np.r_[np.full(3, 0.5 / 3), np.full(n - 3, 0.5 / (n - 3))]
    return rms / np.sqrt(n * weights)


def _rmse(sim: np.ndarray, meas: np.ndarray) -> np.ndarray:
    return np.sqrt(np.nanmean((sim - meas) ** 2, axis=(0, 1)))


@dataclass
class Loaded:
    """The samples a run compares with and what their preprocessing version says about
    them: its name and parameters, its passive PCA (None: r_p not compared) and its
    differentiator (None: the default parameters')."""

    samples: pd.DataFrame
    prep_name: str | None = None
    prep_params: dict = field(default_factory=dict)
    pca: object | None = None
    differentiator: Differentiator | None = None


@dataclass
class Windows:
    """The replay windows of a run and its trial split.

    ``coarse``: the decimated windows candidates are fitted and scored on, ``train`` and
    ``test`` its halves; ``full``: the same windows at the capture rate, where the gap is
    measured, with ``measured`` (window, frame, channel), ``is_test`` (window,) and the
    per-channel ``scales`` of the residual.
    """

    samples: pd.DataFrame
    coarse: WindowSet
    full: WindowSet
    train: WindowSet
    test: WindowSet
    train_ids: list[int]
    test_ids: list[int]
    scales: np.ndarray
    measured: np.ndarray
    is_test: np.ndarray
    phase: np.ndarray
    ra: np.ndarray
    t: np.ndarray


def load(
    store=None,
    prep: str | int | None = None,
    trials: Iterable[int] | None = None,
    samples: pd.DataFrame | None = None,
    passive: bool = True,
) -> Loaded:
    """The samples to replay: ``samples`` if given (only ``trials``), else those of
    version ``prep`` in ``store``; its PCA only with ``passive``."""
    if samples is None:
        if store is None:
            raise DiscrepancyError("run_discrepancy: give a store or a samples frame")
        version = get_version(store, prep)
        loaded = Loaded(
            version.samples(trials),
            version.name,
            version.params,
            version.pca if passive else None,
            version.differentiator(),
        )
    else:
        if trials is not None:
            samples = samples[samples["trial_id"].isin(list(trials))]
        loaded = Loaded(samples)
    if loaded.samples.empty:
        raise DiscrepancyError(
            "no samples to replay: check trials and prep", param=("trials", "prep")
        )
    return loaded


def cut_windows(loaded: Loaded, rs: ReplaySettings, rng: np.random.Generator) -> Windows:
    """Cut the replay windows (decimated and at the capture rate) and split the trials."""
    samples, pca, differ = loaded.samples, loaded.pca, loaded.differentiator
    coarse = make_windows(samples, rs, pca, differ)
    if len(coarse.info) == 0:
        raise DiscrepancyError(
            "every trial is shorter than one replay window "
            f"({rs.warmup_cycles + rs.cycles_per_window} cycles)"
        )
    train_ids, test_ids = split_trials(coarse.info, rng)
    if len(train_ids) < 2 or len(test_ids) < 2:
        raise DiscrepancyError(
            f"need at least 4 trials long enough to replay, have {len(train_ids) + len(test_ids)}"
        )
    # the gap itself (and the parameter refinement) is measured without decimation: the
    # decimated replay's own error would otherwise look like a systematic gap
    full = make_windows(
        samples[samples["trial_id"].isin(coarse.trial_id)], _full_rate(rs), pca, differ
    )
    phase, ra, t = (window_field(full, f) for f in ("phase", "ra", "t"))
    return Windows(
        samples=samples,
        coarse=coarse,
        full=full,
        train=coarse.subset(train_ids),
        test=coarse.subset(test_ids),
        train_ids=train_ids,
        test_ids=test_ids,
        scales=_scales(measured(coarse)),
        measured=measured(full),
        is_test=np.isin(full.trial_id, test_ids),
        phase=phase,
        ra=ra,
        t=t,
    )


def gap_step(w: Windows, model: SimConfig, index: int, rng: np.random.Generator):
    """Replay ``model`` over every window at the capture rate: the `Step` with its
    held-out gap and localisation, and the replay (window, frame, channel)."""
    sim = replay(w.full, [model])[0]
    residual = (sim - w.measured)[..., :3]
    is_test = w.is_test
    _, tl = trial_losses(
        sim[None, is_test], w.measured[is_test], w.scales, w.full.trial_id[is_test]
    )
    k = int(np.flatnonzero(is_test)[0])
    step = Step(
        index=index,
        model=model,
        test_loss=float(tl[0].mean()),
        test_rmse=_rmse(sim[is_test, :, :3], w.measured[is_test, :, :3]),
        test_trial_loss=tl[0],
        localisation=localise(w.full.info, residual, w.phase, w.ra, rng),
        example={
            "trial_id": int(w.full.trial_id[k]),
            "t": w.t[k],
            "measured": w.measured[k, :, :3],
            "simulated": sim[k, :, :3],
        },
    )
    return step, sim


def try_candidates(
    step: Step, w: Windows, opts: DiscrepancyOptions, exclude: set[str], rng, say
) -> None:
    """Fit every observable candidate on the training half and score it held-out, into
    ``step.candidates`` (the unobservable ones into ``step.unobservable``)."""
    current = step.model
    probe = w.train.subset(w.train_ids[:1])
    cands = []
    for c in candidates_for(current, exclude=exclude | set(opts.exclude)):
        if _observable(c, current, probe):
            cands.append(c)
        else:
            step.unobservable.append(c.label)
    for c in cands:
        r = fit_candidate(c, current, w.train, w.scales, opts.fit, rng)
        step.candidates.append(r)
        say(f"  fitted {c.label}: {r.value} in {r.seconds:.1f} s")
    if not step.candidates:
        return
    # the training losses order the held-out tests; a candidate with nothing to fit
    # has none from its fit, so it is replayed here with the model itself
    unfitted = [r for r in step.candidates if r.candidate.param is None]
    _, train = trial_losses(
        replay(w.train, [current] + [r.config for r in unfitted]),
        measured(w.train),
        w.scales,
        w.train.trial_id,
    )
    for r in step.candidates:
        r.train_before = float(train[0].mean())
    for r, loss in zip(unfitted, train[1:], strict=True):
        r.train_after = float(loss.mean())
    score_candidates(step.candidates, current, w.test, w.scales, opts.alpha, opts.fit)


def explain_gap(
    step: Step,
    w: Windows,
    sim: np.ndarray,
    opts: DiscrepancyOptions,
    rng,
    say,
    partial: list | None = None,
):
    """No candidate is significant: test whether the gap is systematic and, if it is and
    above ``gap_floor`` (or an effect named earlier was only ``partial``), correlate it
    with the signals and try a learned correction (with the partial effects' features)."""
    partial = partial or []
    step.decision = "none_significant"
    residual = sim - w.measured
    # systematic = the residual's phase profile repeats across independent halves
    step.systematic = systematic_gap(residual, w.phase, w.full.info, (w.train_ids, w.test_ids))
    residual = residual[..., :3]
    gap = step.systematic[1] < opts.alpha and step.test_loss > opts.gap_floor
    if not (gap or partial):
        return
    step.correlations = residual_correlations(
        w.samples,
        residual[w.is_test],
        w.t[w.is_test],
        w.full.info[w.is_test].reset_index(drop=True),
    )
    if not opts.discover:
        return
    step.discovery = d = discover_step(
        w.full,
        w.samples,
        sim,
        w.measured,
        w.scales,
        w.train_ids,
        opts,
        rng,
        step.model.geometry.middle_length_mm / 2,
        partial,
    )
    say(
        f"  discovered correction ({'added' if d.significant else 'not added'}, "
        f"p {d.p_value:.2g}): held-out loss {np.mean(d.test_before):.4g} -> "
        f"{np.mean(d.test_after):.4g}; leading {', '.join(d.leading[:3])}"
    )
    if d.significant:
        step.decision = "discovered"


def accept(
    step: Step, best: CandidateResult, earlier: list[Step], w: Windows, opts, rng, say
) -> SimConfig:
    """Name ``best`` at ``step`` (refined at the capture rate with ``opts.refine``, and the
    ``earlier`` steps' effects re-fitted with it); returns the model with it added."""
    current = step.model
    train_full = w.full.subset(w.train_ids)
    if opts.refine and best.candidate.param is not None:
        refine_candidate(best, current, train_full, w.scales, opts.fit, rng)
        say(f"  refined {best.candidate.label} at the capture rate: {best.value:.4g} {best.ci}")
    best.accepted = True
    step.accepted = best
    step.decision = "accepted"
    current = best.config
    say(
        f"  named {best.candidate.label} (p_adj {best.p_adjusted:.2g}, "
        f"held-out improvement {best.improvement:.0%})"
    )
    if opts.refine:
        # effects named earlier were fitted without this one: re-fit each once with
        # the others in the model (one pass of coordinate descent), so the reported
        # values and intervals belong to the final model
        for s in earlier:
            r = s.accepted
            if r is None or r.candidate.param is None:
                continue
            refine_candidate(r, current, train_full, w.scales, opts.fit, rng)
            current = r.config
            say(f"  re-fitted {r.candidate.label}: {r.value:.4g} {r.ci}")
    return current


def outcome(steps: list[Step]) -> str:
    """One sentence on what the run found (the last step's decision and the names)."""
    last = steps[-1]
    named = [
        s.accepted.candidate.label + (" (partly)" if s.decision == "partial" else "")
        for s in steps
        if s.accepted
    ]
    d = last.discovery
    if d is not None and d.significant:
        return (
            ("named " + ", ".join(named) + "; then " if named else "")
            + "a systematic gap no candidate explains; learned correction "
            f"({d.physics or 'no term'}: {', '.join(d.leading[:3])}) closes "
            f"{d.improvement:.0%} of the held-out gap"
        )
    if last.correlations is not None:
        top = last.correlations.head(3)
        return (
            "a systematic gap remains that no candidate explains; residual correlates most with "
            + ", ".join(f"{r.signal} ({r.channel}, r={r.r:+.2f})" for r in top.itertuples())
        )
    if named:
        return "named " + ", ".join(named)
    return "nothing named: no candidate improves the held-out fit significantly"


def run_steps(w: Windows, model: SimConfig, opts: DiscrepancyOptions, rng, say):
    """The loop: replay, try the candidates, name the best significant one, repeat, until
    none is significant or ``opts.max_effects`` are named. Returns the steps and the
    final model."""
    steps: list[Step] = []
    current = model
    partial, prev_sim = [], None  # effects found partial (`partial.py`), last replay
    for index in range(opts.max_effects + 1):
        step, sim = gap_step(w, current, index, rng)
        if steps:
            prev = steps[-1]
            prev.gap_closed = 1.0 - step.test_loss / prev.test_loss if prev.test_loss > 0 else 0.0
        steps.append(step)
        say(
            f"step {index}: held-out loss {step.test_loss:.4g}, "
            f"rmse vx {step.test_rmse[0]:.3g} mm/s"
        )
        if prev_sim is not None and steps[-2].accepted is not None:
            partial += check_named(
                steps[-2],
                prev_sim,
                sim,
                w.full,
                w.samples,
                w.measured,
                w.scales,
                w.train_ids,
                opts,
                model.geometry.middle_length_mm / 2,
            )
            c = steps[-2].constancy
            say(
                f"  {c.effect}: {steps[-2].decision} (a varying strength removes "
                f"{c.improvement:.0%} of the rest, p {c.p_value:.2g}, {c.varies_with}"
                f"{'; fit at the edge of its realistic range' if c.at_range_edge else ''})"
            )
        prev_sim = sim
        named = {s.accepted.candidate.effect for s in steps if s.accepted}
        if len(named) >= opts.max_effects:
            step.decision = "max_effects"
            break
        try_candidates(step, w, opts, named, rng, say)
        significant = [r for r in step.candidates if r.significant]
        if not significant:
            explain_gap(step, w, sim, opts, rng, say, partial)
            break
        best = max(significant, key=lambda r: r.improvement)
        current = accept(step, best, steps[:-1], w, opts, rng, say)
    return steps, current


def run_discrepancy(
    store=None,
    prep: str | int | None = None,
    model: SimConfig | None = None,
    name: str | None = None,
    trials: Iterable[int] | None = None,
    options: DiscrepancyOptions | None = None,
    out: str | Path | None = None,
    samples: pd.DataFrame | None = None,
    progress: bool = False,
) -> DiscrepancyResult:
    """Find, name and fix what ``model`` misses about the measured trials.

    Parameters
    ----------
    store : Store, optional
        Source of the samples (``load_samples(store, prep)``) and where the run is
        recorded (tables discrepancy_*); None with ``samples`` given: nothing stored.
    prep : str or int, optional
        Preprocessing version (name or id); None: the only one.
    model : SimConfig, optional
        Starting model (default: the nominal simulator).
    name : str, optional
        Run name (default ``discrepancy-<timestamp>``).
    trials : iterable of int, optional
        Only these trial ids.
    options : DiscrepancyOptions, optional
    out : path, optional
        Report folder (index.html, PNG figures, Markdown/CSV tables); None: no report.
    samples : DataFrame, optional
        A samples frame to use instead of loading one from the store; its rates are
        taken to come from the default preprocessing parameters' differentiator.
    progress : bool
        Print one line per stage on stderr.

    Returns
    -------
    DiscrepancyResult
    """
    started_at = _dt.datetime.now()
    opts = options or DiscrepancyOptions()
    check_options(opts)
    named = name is not None
    name = name or default_name(started_at)
    if out is not None:
        check_writable(out, "out: report folder", DiscrepancyError, param="out")
    if store is None:
        return _run(None, prep, model, name, trials, opts, out, samples, progress, started_at)
    # One writer at a time, from the name check to the stored run: two runs never take
    # the same name or report folder (and migration 016 makes the name unique).
    with store.locked("discrepancy", name):
        if store.path.exists():
            store.upgrade()  # a schema this code cannot write is refused before the work
        if not named:
            name = free_name(store, name)
        check_free(store, name, out)
        return _run(store, prep, model, name, trials, opts, out, samples, progress, started_at)


def _run(store, prep, model, name, trials, opts, out, samples, progress, started_at):
    started, cpu_started = time.perf_counter(), time.process_time()
    say = progress_lines(progress)
    loaded = load(store, prep, trials, samples, opts.passive)
    model = model or SimConfig()
    rng = np.random.default_rng(opts.seed)
    w = cut_windows(loaded, opts.replay or settings_from_prep(loaded.prep_params), rng)
    say(
        f"{len(w.coarse.info)} windows over {len(w.train_ids)} training and "
        f"{len(w.test_ids)} held-out trials"
    )
    steps, current = run_steps(w, model, opts, rng, say)
    result = DiscrepancyResult(
        run_id=None,
        name=name,
        prep_version=loaded.prep_name,
        steps=steps,
        train_trials=w.train_ids,
        test_trials=w.test_ids,
        start_model=model,
        final_model=current,
        outcome=outcome(steps),
        seconds=time.perf_counter() - started,
        cpu_seconds=time.process_time() - cpu_started,
        differentiator=w.coarse.differentiator,
    )
    if out is not None:
        from suds_exp.discrepancy.report import write_report

        result.report_dir = write_report(result, Path(out))
    if store is not None:
        from suds_exp.discrepancy.record import record_run

        result.run_id = record_run(store, result, opts, started_at)
    return result
