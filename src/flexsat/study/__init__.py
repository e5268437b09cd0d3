"""The thesis study end to end and its HTML report (``flexsat study``)."""

from flexsat.study.pipeline import CAMPAIGNS, PARTS, run_study
from flexsat.study.report import format_value, write_report

__all__ = ["CAMPAIGNS", "PARTS", "format_value", "run_study", "write_report"]
