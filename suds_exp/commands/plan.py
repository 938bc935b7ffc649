"""The work behind `suds-exp plan next | loop` (the CLI only parses options and prints):
each returns a JSON-ready dict, and the lines printed without ``--json``."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from suds_exp.commands.simulate import parse_freqs
from suds_exp.plan import LoopOptions, Target, plan_next, run_loop
from suds_exp.sim import SimConfig


def next_command(
    store,
    prep=None,
    goal: str = "map",
    gait_files: Sequence[Path] = (),
    freqs: str | None = None,
    bound: float = 1.3,
    n: int = 1,
    cycles: int = 5,
    out: Path = Path("plan-next"),
    learner: str = "GMR",
    seed: int = 0,
    n_boot: int = 6,
) -> dict:
    """`plan next`: the recommendations of `plan_next` as a dict (the target's files,
    frequencies ``freqs``, e.g. "1/2,1", and bound are checked before the version is read)."""
    target = Target.of(gait_files, parse_freqs(freqs) if freqs else (), bound)
    advice = plan_next(store, prep, goal, target, n, cycles, out, learner, n_boot, seed=seed)
    return advice.to_dict()


def next_lines(doc: dict) -> list[str]:
    """The lines `plan next` prints for `next_command`'s document."""
    lines = [f"version {doc['prep_version']}: {doc['cycles_total']} cycles recorded"]
    for i, rec in enumerate(doc["recommendations"], 1):
        t = rec["trial"]
        lines.append(
            f"{i}. record {t['gait']} at {t['frequency_hz']:g} Hz for {t['cycles']} cycles: "
            f"{rec['reason']}"
        )
    lines += [f"note: {note}" for note in doc.get("notes", [])]
    if doc["stop"]:
        lines.append(doc["stop"]["message"])
    return lines


def loop_options(
    target: Sequence[Path] | None = None, freqs: str | None = None, **recipe
) -> LoopOptions:
    """`plan loop`'s options as a `LoopOptions`: the target's gait files ``target`` and
    frequencies ``freqs`` as "1/2,1" (none: the default target's); the rest of the recipe
    (goal, bound, budget_cycles, seed, cycles, learner, ...) as `LoopOptions` takes it."""
    return LoopOptions(
        target_files=tuple(str(p) for p in target or ()),
        target_frequencies_hz=parse_freqs(freqs) if freqs else (),
        **recipe,
    )


def loop_command(
    store,
    options: LoopOptions,
    prep=None,
    out: Path = Path("plan-loop"),
    config: SimConfig | None = None,
    progress: bool = False,
    say=None,
) -> dict:
    """`plan loop`: run or continue the loop (`run_loop`); its JSON document."""
    return run_loop(store, options, prep, out, config, progress, say).to_dict()


def iteration_line(it) -> str:
    """The line `plan loop` prints for each stored iteration."""
    t = it.trial
    return (
        f"{it.cycles_recorded} cycles: {t['gait']} at {t['frequency_hz']:g} Hz x {t['cycles']} "
        f"({it.reason}); best gait {it.predicted_forward_mm:.1f} mm/cycle predicted, "
        f"{it.achieved_forward_mm:.1f} achieved; map error {it.map_error:.2f} mm"
    )


def loop_lines(doc: dict) -> list[str]:
    """The closing lines of `plan loop` for `loop_command`'s document."""
    last = doc["iterations"][-1]
    stop = doc["stop"]
    return [
        f"loop {doc['loop_id']} ({doc['name']}): {last['cycles_recorded']} cycles recorded, "
        f"{len(doc['iterations']) - 1} planned trials; best gait {last['best_gait']['name']} "
        f"{last['achieved_forward_mm']:.1f} mm/cycle on the simulator",
        stop["reason"],
    ]
