"""Experiment designs: the condition axes a user declares, read from TOML.

An axis has a name (a manifest column), a kind and, for ordered and unordered axes, its
levels:

- ``ordered``: categories in order (the paper's gait axis S+ < S- < O < D- < D+); a
  train/test pair is ``same``, ``near`` (one step apart) or ``far``;
- ``numeric``: a number (the gait frequency in Hz, an amplitude); a pair is ``same``,
  ``lower`` (trained at a lower value than tested) or ``higher``; values are compared
  after rounding to 6 decimals, as `results` stores frequencies;
- ``unordered``: named categories; a pair is ``same`` or ``different``.

The TOML file is a list of ``[[axis]]`` tables with ``name``, ``kind`` and (ordered,
unordered) ``levels``. The axis ``frequency_hz``, when declared, is the gait's cycle
frequency the pipeline needs anyway (every manifest has that column); the other axes
make up a trial's condition label (`ExperimentDesign.label`), the name campaigns and
`results` give a condition (the ``gait`` slot of trials and results). With the paper's
design (`PAPER_DESIGN`, the default) the label is the gait, so nothing stored changes.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, replace
from fractions import Fraction
from importlib.resources import files
from pathlib import Path

from suds_exp.errors import ConfigError

#: Axis kinds and the categories a train/test pair can fall in along each, in display order.
KINDS = {
    "ordered": ("same", "near", "far"),
    "numeric": ("same", "lower", "higher"),
    "unordered": ("same", "different"),
}
#: The axis that is the gait's cycle frequency (a column every manifest has).
FREQUENCY_AXIS = "frequency_hz"
#: Manifest columns that are not condition axes.
RESERVED = ("file", "repeat", "notes")
#: The condition label of a design with no axis but the frequency: recordings without
#: conditions, run by trial (leave-one-trial-out, `suds_exp.campaign.sampling`).
BY_TRIAL_LABEL = "all"
#: Characters a condition label uses to join axes, so no level may contain them (nor
#: the `@` and `,` of condition option strings).
_FORBIDDEN = (";", "=", "@", ",")


@dataclass(frozen=True)
class Axis:
    """One condition axis: ``name`` (a manifest column), ``kind`` (one of `KINDS`),
    ``levels`` (the declared ordered or unordered categories; empty for numeric) and
    ``added`` (levels that code adding trials gave it after the declaration, e.g. the
    gaits `gait design --verify` ran; `suds_exp.ingest.add_trial_levels`). An added level
    of an ordered axis has no place in the declared order: a pair with it is ``same`` or
    ``far``, never ``near``."""

    name: str
    kind: str
    levels: tuple[str, ...] = ()
    added: tuple[str, ...] = ()

    @property
    def all_levels(self) -> tuple[str, ...]:
        """The declared levels, then the added ones."""
        return self.levels + self.added

    @property
    def categories(self) -> tuple[str, ...]:
        """The pair categories along this axis, in display order."""
        return KINDS[self.kind]

    def parse(self, text: str, where: str) -> str | float:
        """A manifest cell of this axis as its value; ``where`` names the file and line.
        Raises `ConfigError` for a number that is not one or a level not declared."""
        text = str(text).strip()
        if self.kind == "numeric":
            try:
                value = float(Fraction(text))
            except (ValueError, ZeroDivisionError):
                value = math.nan
            if not math.isfinite(value) or (self.name == FREQUENCY_AXIS and value <= 0):
                expected = "a positive number of Hz" if self.name == FREQUENCY_AXIS else "a number"
                raise ConfigError(f"{where}: {self.name} {text!r}: expected {expected}")
            return round(value, 6)
        if text not in self.all_levels:
            raise ConfigError(
                f"{where}: {self.name} {text!r} is not a declared level; expected one of "
                f"{', '.join(self.levels)}"
            )
        return text


@dataclass(frozen=True)
class ExperimentDesign:
    """The declared axes, in order, and where they came from (``source``)."""

    axes: tuple[Axis, ...]
    source: str = "built-in"

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.axes)

    def with_added(self, added: dict[str, tuple[str, ...]]) -> ExperimentDesign:
        """This design with ``added`` (axis name -> levels added by code that adds
        trials) appended to its ordered and unordered axes of those names; levels it
        declares or already holds are not repeated."""
        axes = []
        for a in self.axes:
            extra = tuple(v for v in added.get(a.name, ()) if v not in a.all_levels)
            axes.append(replace(a, added=a.added + extra) if extra and a.levels else a)
        return ExperimentDesign(tuple(axes), self.source)

    def declared(self) -> ExperimentDesign:
        """This design as declared: without the levels added after the declaration."""
        return ExperimentDesign(tuple(replace(a, added=()) for a in self.axes), self.source)

    def axis(self, name: str) -> Axis:
        for a in self.axes:
            if a.name == name:
                return a
        raise ConfigError(f"{self.source}: no axis {name!r}; declared: {', '.join(self.names)}")

    @property
    def by_trial(self) -> bool:
        """No axis but perhaps the frequency: trials are run leave-one-trial-out."""
        return not self.label_axes

    @property
    def label_axes(self) -> tuple[Axis, ...]:
        """The axes that make up a condition label (all but the frequency)."""
        return tuple(a for a in self.axes if a.name != FREQUENCY_AXIS)

    @property
    def added_labels(self) -> frozenset[str]:
        """Labels of the conditions whose level code added after the declaration (its one
        condition axis's `Axis.added`; none with several condition axes)."""
        axes = self.label_axes
        return frozenset(axes[0].added) if len(axes) == 1 else frozenset()

    def label(self, values: dict[str, str | float]) -> str:
        """A condition's label from its axis values: the value of the one label axis
        (the paper's: the gait), ``name=value`` joined by ``;`` for several, ``all`` for
        none (recordings without conditions)."""
        parts = [(a.name, _text(values[a.name])) for a in self.label_axes]
        if not parts:
            return BY_TRIAL_LABEL
        if len(parts) == 1:
            return parts[0][1]
        return ";".join(f"{n}={v}" for n, v in parts)

    def values(self, label: str, frequency_hz: float | None = None) -> dict[str, str | float]:
        """The axis values of a condition (the inverse of `label`); the frequency, when it
        is an axis, from ``frequency_hz``."""
        axes = self.label_axes
        out: dict[str, str | float] = {}
        if len(axes) == 1:
            out[axes[0].name] = _value(axes[0], label)
        elif len(axes) > 1:
            pieces = dict(p.split("=", 1) for p in label.split(";") if "=" in p)
            for a in axes:
                if a.name not in pieces:
                    raise ConfigError(
                        f"{self.source}: condition {label!r} has no value of axis {a.name!r}"
                    )
                out[a.name] = _value(a, pieces[a.name])
        if FREQUENCY_AXIS in self.names:
            out[FREQUENCY_AXIS] = round(float(frequency_hz), 6)
        return out


def level_problem(level: str) -> str | None:
    """Why ``level`` cannot be a level's name (empty, padded, or holding a character a
    condition label or option string uses), or None when it can."""
    if not isinstance(level, str) or not level or level.strip() != level:
        return "expected a name without leading or trailing spaces"
    bad = [c for c in _FORBIDDEN if c in level]
    return f"contains one of {' '.join(_FORBIDDEN)}" if bad else None


def _text(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def _value(axis: Axis, text: str):
    return float(text) if axis.kind == "numeric" else text


def design_from_dict(data: dict, source: str) -> ExperimentDesign:
    """An `ExperimentDesign` from the parsed TOML ``data``; ``source`` names the file in
    errors (one line each, `ConfigError`)."""
    entries = data.get("axis", [])
    unknown = sorted(set(data) - {"axis"})
    if unknown:
        raise ConfigError(f"{source}: unknown entry {unknown[0]!r}; expected [[axis]] tables")
    if not isinstance(entries, list):
        raise ConfigError(f"{source}: axis: expected [[axis]] tables")
    axes: list[Axis] = []
    for i, entry in enumerate(entries, start=1):
        where = f"{source}: axis {i}"
        if not isinstance(entry, dict):
            raise ConfigError(f"{where}: expected a table with name, kind and levels")
        extra = sorted(set(entry) - {"name", "kind", "levels"})
        if extra:
            raise ConfigError(f"{where}: unknown key {extra[0]!r}; expected name, kind, levels")
        name = entry.get("name")
        if not isinstance(name, str) or not name.isidentifier():
            raise ConfigError(f"{where}: name {name!r}: expected a column name (letters, _)")
        where = f"{source}: axis {name!r}"
        if name in RESERVED:
            raise ConfigError(f"{where}: {name!r} is a manifest column, not an axis")
        if any(a.name == name for a in axes):
            raise ConfigError(f"{where}: declared twice")
        kind = entry.get("kind")
        if kind not in KINDS:
            raise ConfigError(f"{where}: kind {kind!r}; expected one of {', '.join(KINDS)}")
        levels = entry.get("levels", [])
        if kind == "numeric":
            if levels:
                raise ConfigError(f"{where}: a numeric axis has no levels")
        else:
            if (
                not isinstance(levels, list)
                or len(levels) < 2
                or not all(isinstance(v, str) and v.strip() == v and v for v in levels)
            ):
                raise ConfigError(f"{where}: levels: expected a list of at least two names")
            if len(set(levels)) != len(levels):
                raise ConfigError(f"{where}: levels: a name is listed twice")
            bad = [v for v in levels if any(c in v for c in _FORBIDDEN)]
            if bad:
                raise ConfigError(
                    f"{where}: level {bad[0]!r} contains one of {' '.join(_FORBIDDEN)}"
                )
        if name == FREQUENCY_AXIS and kind != "numeric":
            raise ConfigError(f"{where}: the gait frequency is numeric")
        axes.append(Axis(name, kind, tuple(levels)))
    return ExperimentDesign(tuple(axes), source)


def load_design(path: Path | str | None = None) -> ExperimentDesign:
    """The design in the TOML file at ``path`` (None: the paper's, `PAPER_DESIGN`)."""
    if path is None:
        return PAPER_DESIGN
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such experiment description") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: not valid TOML ({exc})") from None
    return design_from_dict(data, str(path))


def _paper() -> ExperimentDesign:
    text = files("suds_exp.experiment").joinpath("paper.toml").read_text(encoding="utf-8")
    return design_from_dict(tomllib.loads(text), "paper")


#: The paper's design: gait (ordered S+ < S- < O < D- < D+) and frequency_hz (numeric).
PAPER_DESIGN = _paper()


def is_paper(design: ExperimentDesign | None) -> bool:
    """Whether ``design`` is the paper's (None counts as the paper's)."""
    return design is None or design.axes == PAPER_DESIGN.axes


def same_value(a, b) -> bool:
    """Equality of two axis values (numbers after rounding to 6 decimals)."""
    if isinstance(a, float) or isinstance(b, float):
        return math.isclose(round(float(a), 6), round(float(b), 6), abs_tol=0.0)
    return a == b
