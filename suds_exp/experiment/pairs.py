"""How a train/test pair of conditions is classified along each axis of a design.

Ordered axis: ``same``, ``near`` (one step along the declared levels) or ``far``; numeric:
``same`` (equal after rounding to 6 decimals), ``lower`` (trained at a lower value than
tested) or ``higher``; unordered: ``same`` or ``different``. On the paper's design the gait
categories are the ``gait_sim`` of ``results_labelled`` and the frequency categories its
``period_rel`` read the other way round (trained at a lower frequency = model-period
``>`` data-period).
"""

from __future__ import annotations

from suds_exp.experiment.design import Axis, ExperimentDesign

#: The column of labelled results holding the pair category along an axis.
PAIR_SUFFIX = "_pair"


def pair_column(axis: Axis | str) -> str:
    """``gait`` -> ``gait_pair``: the column of an axis's pair category."""
    return f"{axis if isinstance(axis, str) else axis.name}{PAIR_SUFFIX}"


def classify(axis: Axis, train, test) -> str:
    """The category of a pair whose training value is ``train`` and test value ``test``."""
    if axis.kind == "numeric":
        a, b = round(float(train), 6), round(float(test), 6)
        return "same" if a == b else ("lower" if a < b else "higher")
    if axis.kind == "ordered":
        if train == test:
            return "same"
        if train in axis.added or test in axis.added:
            # an added level has no place in the declared order (see `Axis`)
            return "far"
        steps = abs(axis.levels.index(train) - axis.levels.index(test))
        return "same" if steps == 0 else ("near" if steps == 1 else "far")
    return "same" if train == test else "different"


def classify_pair(
    design: ExperimentDesign,
    train: tuple[str, float],
    test: tuple[str, float],
) -> dict[str, str]:
    """Axis name -> category of a pair of conditions ``(label, frequency_hz)``."""
    a, b = design.values(*train), design.values(*test)
    return {axis.name: classify(axis, a[axis.name], b[axis.name]) for axis in design.axes}
