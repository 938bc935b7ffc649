"""Analysis of campaign results: similarity categories, GLM, IQR, sample efficiency, the
paper's findings, report.

The labels come from the SQL views of migration 004 (``results_labelled`` and friends);
every table of the report is also a function returning a DataFrame::

    from suds_exp.analysis import load_results, glm_table
    results = load_results(Store("suds.duckdb"), "paper")
    glm = glm_table(results)
"""

from suds_exp.analysis.categories import GAIT_AXIS, category_table, main_cycles
from suds_exp.analysis.findings import FINDINGS, findings, findings_summary, findings_table
from suds_exp.analysis.glm import glm_table
from suds_exp.analysis.paper import agreement_summary, compare_glm, compare_iqr, paper_table
from suds_exp.analysis.queries import campaigns, load_results
from suds_exp.analysis.report import iqr_wide, report_tables, write_report
from suds_exp.analysis.spread import iqr_table, slope_table
from suds_exp.errors import AnalysisError

__all__ = [
    "FINDINGS",
    "GAIT_AXIS",
    "AnalysisError",
    "agreement_summary",
    "campaigns",
    "category_table",
    "compare_glm",
    "compare_iqr",
    "findings",
    "findings_summary",
    "findings_table",
    "glm_table",
    "iqr_table",
    "iqr_wide",
    "load_results",
    "main_cycles",
    "paper_table",
    "report_tables",
    "slope_table",
    "write_report",
]
