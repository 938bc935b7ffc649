"""`suds-exp findings`: the findings table and what the passive shape adds, on the terminal."""

from __future__ import annotations

import pandas as pd

from suds_exp import console
from suds_exp.analysis.findings import findings, findings_display, findings_headline, findings_json
from suds_exp.analysis.momentum_info import (
    MOMENTUM_EXPLANATION,
    campaign_momentum_information,
    momentum_display,
    momentum_reason,
)
from suds_exp.analysis.passive import (
    PASSIVE_EXPLANATION,
    campaign_passive_information,
    passive_display,
    passive_reason,
)
from suds_exp.errors import ConfigError


def show_findings(store, name: str, n_boot: int = 400, seed: int = 0, as_json=False) -> None:
    """Measure the findings of campaign ``name`` and what the passive shape adds, and print
    them: tables and headline, or one JSON document (`findings_json` with a
    ``passive_information`` and a ``momentum_information`` list)."""
    table = findings(store, name, n_boot=n_boot, seed=seed)
    passive = campaign_passive_information(store, name, n_boot=n_boot, seed=seed)
    momentum = campaign_momentum_information(store, name, n_boot=n_boot, seed=seed)
    if as_json:
        doc = findings_json(table, name)
        doc["passive_information"] = passive.to_dict(orient="records")
        doc["momentum_information"] = momentum.to_dict(orient="records")
        console.print_json(doc)
    else:
        print_findings(table, name)
        print_passive_information(passive)
        print_momentum_information(momentum)


FINDINGS_TABLES = ("findings", "passive", "momentum")


def findings_frame(store, name: str, table: str = "findings", n_boot: int = 400, seed: int = 0):
    """One of `findings`' tables as a DataFrame, unrounded: ``findings`` (F1-F10),
    ``passive`` (what the passive shape adds) or ``momentum`` (what the velocity history
    adds). Only the table asked for is measured."""
    measure = {
        "findings": findings,
        "passive": campaign_passive_information,
        "momentum": campaign_momentum_information,
    }
    if table not in measure:
        raise ConfigError(
            f"table {table!r}: expected one of {', '.join(FINDINGS_TABLES)}", param="table"
        )
    return measure[table](store, name, n_boot=n_boot, seed=seed)


def print_findings(table: pd.DataFrame, campaign: str) -> None:
    """Print the findings table and its headline on the terminal; on a design other than
    the paper's (`for_design`), first its caveat and then what was left out."""
    if "caveat" in table.attrs:
        console.out.print(table.attrs["caveat"] + ".")
    console.print_frame(findings_display(table), title=f"the paper's findings on {campaign}")
    console.out.print(findings_headline(table))
    if table.attrs.get("left_out"):
        console.out.print("not measurable on this design: " + "; ".join(table.attrs["left_out"]))


def print_passive_information(table: pd.DataFrame) -> None:
    """Print the passive-information table and its explanation on the terminal."""
    if table.empty:
        console.out.print(f"what the passive shape adds: not measurable ({passive_reason(table)})")
        return
    console.print_frame(passive_display(table), title="what the passive shape adds")
    console.out.print(PASSIVE_EXPLANATION)


def print_momentum_information(table: pd.DataFrame) -> None:
    """Print the momentum-information table and its explanation on the terminal."""
    if table.empty:
        reason = momentum_reason(table)
        console.out.print(f"what the velocity history adds: not measurable ({reason})")
        return
    console.print_frame(momentum_display(table), title="what the velocity history adds")
    console.out.print(MOMENTUM_EXPLANATION)
