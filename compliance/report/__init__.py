"""HTML and PDF reports: compliance (``govcheck check --report``, ``govcheck report``) and model validation.

``render_report(results, html_path=None, pdf_path=None)`` and
``render_validation_report(result, html_path, pdf_path=None)``; see docs/report.md.
"""

from compliance.report.render import render_report, render_validation_report

__all__ = ["render_report", "render_validation_report"]
