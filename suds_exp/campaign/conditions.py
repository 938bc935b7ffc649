"""Experimental conditions (gait, frequency) and the option strings that name them.

A condition is a tuple ``(gait, frequency_hz)`` with the frequency rounded to 6 decimals,
as stored in `results` (1/3 Hz -> 0.333333). Option strings list conditions separated by
commas; each item is ``GAIT@FREQ`` (one condition), ``GAIT`` (that gait at every
frequency present) or ``@FREQ`` (every gait at that frequency); FREQ may be a fraction.
"""

from __future__ import annotations

from suds_exp.errors import CampaignError, ConfigError
from suds_exp.robot import GAITS, parse_frequency, parse_ids

Condition = tuple[str, float]


def round_hz(frequency_hz: float) -> float:
    """A frequency in Hz rounded to 6 decimals, the form stored in `results`."""
    return round(float(frequency_hz), 6)


def condition_sort_key(cond: Condition) -> tuple[int, str, float]:
    """The paper's gaits in their order (S+ S- O D- D+), then other gait labels
    alphabetically; frequency last. Total on distinct conditions: the conditions come out
    of sets, whose order changes with PYTHONHASHSEED, and a resumed campaign's plan must
    equal the stored one."""
    gait, f = cond
    if gait in GAITS:
        return (GAITS.index(gait), "", f)
    return (len(GAITS), gait, f)


def format_condition(cond: Condition) -> str:
    """``"O@0.5"``: the condition as an option string item."""
    return f"{cond[0]}@{cond[1]:g}"


def _parse_hz(text: str, option: str) -> float:
    try:
        value = parse_frequency(text)
    except ValueError:
        raise CampaignError(
            f"{option}: frequency {text!r} is not a positive number; write e.g. 0.5 or 1/3",
            param=option,
        ) from None
    return round_hz(value)


def select_conditions(spec: str | None, available: list[Condition], option: str) -> list[Condition]:
    """The conditions of ``available`` named by the option string ``spec`` (None: all).

    Returns them sorted along the gait axis, then by frequency; an item that matches no
    available condition is an error naming it and what is available.
    """
    pool = sorted(set(available), key=condition_sort_key)
    if spec is None or not spec.strip():
        return pool
    chosen: set[Condition] = set()
    for item in (s.strip() for s in spec.split(",")):
        if not item:
            continue
        gait, _, hz = item.partition("@")
        gait = gait.strip()
        # a user design's conditions are named by their labels (`suds_exp.experiment`)
        known = dict.fromkeys((*GAITS, *(c[0] for c in pool)))
        if gait and gait not in known:
            raise CampaignError(
                f"{option}: gait {gait!r} in {item!r}; expected one of {' '.join(known)}",
                param=option,
            )
        f = _parse_hz(hz, option) if hz.strip() else None
        match = [c for c in pool if (not gait or c[0] == gait) and (f is None or c[1] == f)]
        if not match:
            have = ", ".join(format_condition(c) for c in pool) or "none"
            raise CampaignError(
                f"{option}: {item!r} matches no condition in the samples (have: {have})",
                param=option,
            )
        chosen.update(match)
    return sorted(chosen, key=condition_sort_key)


def parse_int_list(spec: str | None, option: str) -> list[int]:
    """``"1-10,21,30"`` -> [1, ..., 10, 21, 30] (sorted, unique); ``"paper"`` -> the
    paper's sample-efficiency sweep; None or empty -> []."""
    if spec is None or not spec.strip():
        return []
    if spec.strip() == "paper":
        return list(PAPER_SWEEP)
    try:
        return parse_ids(spec, option)
    except ConfigError as exc:
        raise CampaignError(str(exc), param=exc.param) from None


#: Training cycles of the paper's sample-efficiency figure.
PAPER_SWEEP = (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 21, 30, 39, 48)
