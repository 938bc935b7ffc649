"""`suds-exp survey`: the survey's tables and sentence on the terminal."""

from __future__ import annotations

from suds_exp import console
from suds_exp.commands.messages import user_message
from suds_exp.errors import AnalysisError, ConfigError


def print_survey(tables: dict, cycles: int) -> None:
    """Print `survey_tables`' tables (cycles to target, timing, GLM), the data-ratio
    sentence and why anything was left out, in the command line's words."""
    from suds_exp.analysis.survey import ratio_sentence

    if "cycles" in tables:
        console.print_frame(tables["cycles"].round(2), title="cycles to target (median RMSE vx)")
    console.print_frame(tables["timing"].round(3), title="median fit / predict seconds")
    if "glm" in tables:
        console.print_frame(tables["glm"].round(3), title="GLM, learner as a factor (100 ln)")
    if "ratio" in tables:
        console.out.print(ratio_sentence(tables["ratio"], cycles))
    for why in tables.get("missing", []):
        console.out.print(f"left out: {user_message(why)}")


SURVEY_TABLES = ("cycles", "timing", "glm")


def survey_frame(tables: dict, table: str = "cycles"):
    """One of `survey_tables`' tables as a flat DataFrame (its index as columns), for CSV.

    ``cycles`` needs a sweep and ``glm`` cross pairs at the main size; asking for one the
    campaign cannot give raises the `AnalysisError` that left it out.
    """
    if table not in SURVEY_TABLES:
        raise ConfigError(
            f"table {table!r}: expected one of {', '.join(SURVEY_TABLES)}", param="table"
        )
    if table not in tables:
        why = "; ".join(map(str, tables.get("missing", []))) or "not measured"
        raise AnalysisError(f"table {table!r}: not measurable on this campaign ({why})")
    frame = tables[table]
    named = [n for n in frame.index.names if n is not None]
    return frame.reset_index() if named else frame
